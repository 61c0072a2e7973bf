#!/usr/bin/python3
"""A finished run is reused only by the binary that made it, with the same inputs
(experiments/runstore.py); `--version` and every run file name the binary.

A test double stands for "a rebuild at another commit": a script that answers --version with
another build identity and otherwise runs the real binary. Usage: run_identity_test.py SANDBENCH
"""
import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
sys.path.insert(0, str(ROOT / "experiments"))
import engines  # noqa: E402
import sbrun  # noqa: E402

failures = []


def expect(what, got, wanted):
    if got != wanted:
        failures.append(f"{what}: got {got}, expected {wanted}")
    print(f"{'ok  ' if got == wanted else 'FAIL'} {what}: {sorted(got) if isinstance(got, set) else got}")


class CountingEngine(engines.LocalEngine):
    """The local engine, remembering which runs it executed."""

    def __init__(self):
        super().__init__(jobs=2)
        self.executed = set()

    def execute(self, specs, label="runs"):
        self.executed |= {s["name"] for s in specs}
        super().execute(specs, label)


def main():
    real = str(Path(sys.argv[1]).resolve())
    version = subprocess.run([real, "--version"], capture_output=True, text=True, check=True).stdout.strip()
    m = re.search(r"commit (\S+) build ([0-9a-f]{16})", version)
    expect("--version names a commit and a 16-digit build identity", bool(m), True)
    if not m:
        sys.exit(f"--version printed {version!r}")
    commit, build = m.groups()
    # The stamp's commit is the last one that changed the binary's folders (all of them).
    dirs = ["common", "grid", "tin", "harness", "cmake", "CMakeLists.txt", "CMakePresets.json"]
    git = subprocess.run(["git", "-C", str(ROOT), "log", "-1", "--format=%h", "--abbrev=12", "--", *dirs],
                         capture_output=True, text=True)
    if git.returncode == 0 and git.stdout.strip():
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--", *dirs],
                               capture_output=True, text=True).stdout.strip()
        expect("--version's commit is the last commit of the sources", commit,
               git.stdout.strip() + ("-dirty" if dirty else ""))
    with tempfile.TemporaryDirectory(prefix="sbident-") as tmp:
        tmp = Path(tmp)
        other = tmp / "other-sandbench"
        other.write_text(f"#!/bin/sh\nif [ \"$1\" = --version ]; then\n"
                         f"  echo 'sandbench 0.1.0 commit 0123456789ab build 00000000deadbeef (test double)'\n"
                         f"  exit 0\nfi\nexec {real} \"$@\"\n")
        other.chmod(0o755)
        scenes = [tmp / "a.toml", tmp / "b.toml"]
        for s in scenes:
            shutil.copyfile(sbrun.DIAGONAL_SCENE, s)
        quick = [sbrun.diagonal_path(0.05), "grid.cell_m=0.02"]
        jobs = [(scenes[0], "grid", "a", quick), (scenes[1], "grid", "b", quick)]

        def sweep(binary, jobs=jobs):
            engine = CountingEngine()
            ctx = sbrun.Context(binary, tmp / "results", "tiny", engine=engine)
            ctx.run_many("identity", jobs)
            return engine.executed

        expect("first sweep runs everything", sweep(real), {"a", "b"})
        expect("the same binary again reuses everything", sweep(real), set())
        expect("another binary reuses nothing", sweep(str(other)), {"a", "b"})
        side = json.loads((tmp / "results" / "runs" / "a.json").read_text())
        expect("the sidecar records the other binary", side["binary"]["build_id"], "00000000deadbeef")
        expect("back to the first binary: runs again", sweep(real), {"a", "b"})
        scenes[1].write_text(scenes[1].read_text() + "\n# an edit\n")
        expect("an edited scene file reruns only its run", sweep(real), {"b"})
        changed = [(scenes[0], "grid", "a", quick + ["grid.neighbours=4"]), jobs[1]]
        expect("another override reruns only its run", sweep(real, changed), {"a"})
        (tmp / "results" / "runs" / "b.h5").unlink()
        expect("a missing run file reruns its run", sweep(real, changed), {"b"})

        import h5py
        with h5py.File(tmp / "results" / "runs" / "a.h5", "r") as f:
            recorded = {k: f.attrs[k].decode() if isinstance(f.attrs[k], bytes) else str(f.attrs[k])
                        for k in ("commit", "build_id")}
        expect("the run file records the binary's commit and build", recorded, {"commit": commit, "build_id": build})
    if failures:
        sys.exit("\n".join(f"FAIL: {f}" for f in failures))
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
