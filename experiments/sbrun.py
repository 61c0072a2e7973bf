"""Shared helpers for experiment scripts: run sandbench, read run files and summaries.

Runs are resumable: a run file that exists is complete (sandbench writes it under a
temporary name and renames it when whole), so it is not run again.
"""
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "experiments" / "scenes"


def sandbench_path(explicit=None):
    if explicit:
        return Path(explicit)
    return ROOT / "build" / "release" / "harness" / "sandbench"


def run(sandbench, scene, backend, out, overrides=(), quiet=True):
    """Runs one back-end on a scene (skipped when `out` exists); returns the summary dict."""
    out = Path(out)
    summary_path = out.with_suffix(".json")
    if out.exists() and summary_path.exists():
        return json.loads(summary_path.read_text())
    out.parent.mkdir(parents=True, exist_ok=True)
    cmd = [str(sandbench), "run", str(scene), "--backend", backend, "--out", str(out), "--json"]
    for o in overrides:
        cmd += ["--set", o]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.stderr.write(proc.stderr)
        raise RuntimeError(f"sandbench failed ({proc.returncode}): {' '.join(cmd)}")
    summary = json.loads(proc.stdout)
    tmp = summary_path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(summary, indent=2) + "\n")
    tmp.replace(summary_path)
    return summary


def progress(message):
    sys.stderr.write(message + "\n")
    sys.stderr.flush()
