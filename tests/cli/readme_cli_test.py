#!/usr/bin/python3
"""The README's usage lines name exactly the options each command accepts: for every
subcommand of `sandbench --help`, every option of `sandbench COMMAND --help` (but --help) is
named on the README's `sandbench COMMAND ...` lines in its code blocks (continuation lines
included), by its long or its short name, and every flag those lines name is an option. A flag
added without the README, or one the README keeps after it went, fails.

Usage: readme_cli_test.py SANDBENCH"""
import re
import subprocess
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"
FLAG = re.compile(r"(?<![\w-])--?[a-zA-Z][a-z0-9-]*")


def help_text(sandbench, *args):
    proc = subprocess.run([sandbench, *args, "--help"], capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"sandbench {' '.join(args)} --help failed: {proc.stderr}")
    return proc.stdout


def commands(sandbench):
    """The subcommands listed under 'Subcommands:' in the top-level help."""
    text = help_text(sandbench)
    section = text.split("Subcommands:", 1)[1] if "Subcommands:" in text else ""
    return [m.group(1) for m in re.finditer(r"^\s{2}([a-z][a-z-]*)\s", section, re.M)]


def cli_options(sandbench, command):
    """Each option's names ({'-o', '--out'}), --help left out."""
    text = help_text(sandbench, command)
    section = text.split("Options:", 1)[1] if "Options:" in text else text
    options = []
    for line in section.splitlines():
        head = line.strip()
        if head.startswith("-"):  # an option's own line: its names, comma-separated, before its type
            names = {n.split("{")[0] for n in head.split()[0].split(",")}
            if "--help" not in names:
                options.append(names)
    return options


def readme_flags():
    """{command: flags} from the usage lines in the README's code blocks."""
    usage, current = {}, None
    blocks = re.findall(r"^```[a-z]*\n(.*?)^```", README.read_text(), re.S | re.M)
    for block in blocks:
        current = None
        for line in block.splitlines():
            m = re.match(r"sandbench ([a-z][a-z-]*)", line)
            if m:
                current = m.group(1)
                usage.setdefault(current, set()).update(FLAG.findall(line[m.end():]))
            elif current and line.startswith(" ") and line.strip():
                usage[current].update(FLAG.findall(line))
            else:
                current = None
    return usage


def main():
    sandbench = sys.argv[1]
    documented = readme_flags()
    failures = []
    names = commands(sandbench)
    if not names:
        sys.exit("no subcommands found in `sandbench --help`")
    for command in names:
        if command == "help":
            continue
        options = cli_options(sandbench, command)
        doc = documented.get(command)
        if doc is None:
            failures.append(f"{command}: no `sandbench {command} ...` usage line in README.md")
            continue
        missing = [",".join(sorted(o)) for o in options if not o & doc]
        if missing:
            failures.append(f"{command}: accepts {missing}, which README.md's usage lines do not name")
        unknown = sorted(doc - set().union(*options))
        if unknown:
            failures.append(f"{command}: README.md names {unknown}, which the command does not accept")
    for f in failures:
        print("FAIL", f)
    print(f"{len(names) - len(failures)} commands match, {len(failures)} failures")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
