"""REPORT.md from the experiments' values: each experiment's `run(ctx)` returns a dict of values
(numbers, Markdown tables, figure file names, verdict words computed from the numbers) and its
section's text is the Jinja2 template experiments/report/<key>.md.j2, filled from that dict.
StrictUndefined: a placeholder without a value fails the reproduction instead of printing nothing.

A value dict may hold `summary`: {back-end label: {column: formatted value}}; the report's summary
table merges them (SUMMARY_COLUMNS, in that order; a column no experiment fills is left out).
Back-end labels are the CLI's back-end names (`tin`, `grid`, `sparse`), optionally followed by a
setting in words (`tin curved`)."""
import math
import re
from pathlib import Path

import jinja2

TEMPLATES = Path(__file__).resolve().parent / "report"

SUMMARY_COLUMNS = ["step time", "settling time", "memory at equal accuracy", "accuracy vs analytic references",
                   "accuracy vs particle sand", "stability", "haptic force quality", "interactive frame rate"]
BACKEND_ORDER = ["tin", "grid", "sparse"]

# The report's parts in order: (heading, the question in a sentence, experiment keys). An experiment
# not named here goes to the end, so no section is ever dropped.
PARTS = [
    ("The paper's figures and the speed bars",
     "Does our implementation reproduce the paper's timing and size claims, and how fast is each back-end on "
     "the shipped scenes?", ["fig5_6", "fig7", "fig8_9", "alpha_flat", "drift", "bars"]),
    ("Memory", "Does a TIN need less memory than a grid of the same accuracy?", ["memory"]),
    ("Accuracy and orientation", "How close does each back-end come to analytic sand at rest, at any orientation?",
     ["accuracy", "orientation", "pile_relax", "pile_positions"]),
    ("Against particle sand", "How far is each back-end from granular particles on the same stroke, and is that the "
     "shared tool model or the discretisation?", ["particles"]),
    ("Settling", "How does the time to come to rest grow with resolution, and what does the cascade cost?",
     ["settling", "cascade"]),
    ("Stability and cliffs", "Does any input crash a back-end or make its cost explode?", ["stability", "cliffs"]),
    ("Interactive use", "What force does the hand feel on each back-end, and does the window keep up as the "
     "domain grows?", ["haptics", "interactive_scaling"]),
    ("The sparse grid", "Does a sparse grid keep the paper's memory promise without the TIN's costs?", ["sparse"]),
]


# Verdict words, computed from numbers: a template never states a comparison its values do not make.
def times(a, b, better="faster", worse="slower"):
    """'2.3x slower' when a is 2.3 times b (for times: larger is worse), '1.5x faster' when b is 1.5 times a."""
    if not (a > 0 and b > 0):
        return "not comparable"
    return f"{a / b:.2f}x {worse}" if a >= b else f"{b / a:.2f}x {better}"


def within(value, bar):
    """'within' when value <= bar, else 'outside'."""
    return "within" if value <= bar else "outside"


def reproduced(ok):
    return "reproduced" if ok else "not reproduced"


def method_or_code(is_method):
    """Who loses: 'the method' (the representation or rule) or 'our code' (a fixable implementation)."""
    return "the method" if is_method else "our code"


def fmt(value, spec):
    """format(value, spec), or the value as it is when it is not a number (an empty table cell)."""
    if isinstance(value, (int, float)) and not (isinstance(value, float) and math.isnan(value) and spec[-1] in "fe"):
        return format(value, spec)
    return str(value)


def _environment():
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(TEMPLATES)), undefined=jinja2.StrictUndefined,
                             keep_trailing_newline=True, trim_blocks=True, lstrip_blocks=True, autoescape=False)
    env.filters["f"] = fmt
    env.globals.update(times=times, within=within, reproduced=reproduced, method_or_code=method_or_code)
    return env


ENV = _environment()


def render(key, values):
    """Experiment KEY's section from its values (experiments/report/KEY.md.j2)."""
    return ENV.get_template(f"{key}.md.j2").render(**values)


def summary_table(all_values):
    """The summary table (Markdown) merged from every experiment's `summary`; '' if none has one."""
    cells = {}
    for values in all_values.values():
        for backend, cols in values.get("summary", {}).items():
            row = cells.setdefault(backend, {})
            for col, text in cols.items():
                row[col] = f"{row[col]}; {text}" if col in row else text
    if not cells:
        return ""
    extra = sorted({c for row in cells.values() for c in row} - set(SUMMARY_COLUMNS))
    columns = [c for c in SUMMARY_COLUMNS + extra if any(c in row for row in cells.values())]

    def order(backend):
        base = backend.split()[0]
        return (BACKEND_ORDER.index(base) if base in BACKEND_ORDER else len(BACKEND_ORDER), backend)

    md = "| back-end | " + " | ".join(columns) + " |\n|" + "---|" * (len(columns) + 1) + "\n"
    for backend in sorted(cells, key=order):
        md += f"| {backend} | " + " | ".join(cells[backend].get(c, "") for c in columns) + " |\n"
    return md


def sections(all_values):
    """The sections in the report's order, under their parts' headings."""
    out, done = [], set()
    for title, question, keys in PARTS:
        present = [k for k in keys if k in all_values]
        if not present:
            continue
        out.append(f"## {title}\n\n*{question}*\n")
        out += [render(k, all_values[k]) for k in present]
        done.update(present)
    rest = [k for k in all_values if k not in done]
    if rest:
        out.append("## Other experiments\n")
        out += [render(k, all_values[k]) for k in rest]
    return out


def assemble(header, all_values):
    """The whole report: title and machine, abstract, summary table, then the sections."""
    abstract = ENV.get_template("abstract.md.j2").render(v=all_values)
    table = summary_table(all_values)
    return ("# sandbench: reproducing Purchart's TIN sand model\n\n" + header + "\n" + abstract + "\n" +
            (table + "\n" if table else "") + "\n".join(sections(all_values)))


def prose_words(markdown):
    """Words of prose in a Markdown text: tables, figures, code blocks and headings' markup excluded."""
    text = re.sub(r"```.*?```", " ", markdown, flags=re.S)
    words = 0
    for line in text.splitlines():
        s = line.strip()
        if s.startswith("|") or s.startswith("!["):
            continue
        s = re.sub(r"`[^`]*`", "x", s)  # a code span counts as one word
        words += len(re.findall(r"[A-Za-z0-9][\w'.,/-]*", s))
    return words


if __name__ == "__main__":
    import sys
    for p in sys.argv[1:]:
        print(f"{p}: {prose_words(Path(p).read_text())} words of prose")
