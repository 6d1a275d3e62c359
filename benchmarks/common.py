"""What the benchmarks share: a run timed as ``meshwear run`` takes it, and
the generated section of a docs page."""

import tempfile
import time
from pathlib import Path

from meshwear.model.build import build_model, check_time_step, initial_state
from meshwear.output.recorder import RunRecorder, summary
from meshwear.step.simulate import run


def timed_run(scene):
    """Build, run and write the outputs of ``scene`` (into a temporary
    folder), as ``meshwear run`` does; return the model, the final state,
    its ``summary.json`` object and the wall time (s)."""
    start = time.perf_counter()
    model = build_model(scene)
    check_time_step(model)
    state = initial_state(model)
    with tempfile.TemporaryDirectory() as out:
        recorder = RunRecorder(out, model)
        run(model, state, observers=[recorder])
        result = summary(model, state, time.perf_counter() - start)
        recorder.close(result)
    return model, state, result, time.perf_counter() - start


def replace_section(page, start, end, section):
    """Put ``section`` (text from the ``start`` marker to the ``end`` one)
    in place of the page's, or append it if the page has none."""
    text = page.read_text()
    if start in text:
        text = text[:text.index(start)] + section + text[text.index(end) + len(end):]
    else:
        text = text.rstrip("\n") + "\n\n" + section + "\n"
    page.write_text(text)


def write_measured(name, rows, figure, caption, section=None):
    """The measured section of docs/examples/``name``.md, as
    benchmarks/``name``.py writes it: a table of ``rows`` ((quantity,
    measured) pairs) and the figure docs/img/``figure`` under ``caption``;
    ``section`` names the section's markers if the page has more than one."""
    section = section or name
    start, end = f"<!-- {section}:start -->", f"<!-- {section}:end -->"
    lines = [start, "", f"<!-- written by benchmarks/{name}.py -->", "",
             "| quantity | measured |", "|---|---:|"]
    lines += [f"| {quantity} | {value} |" for quantity, value in rows]
    lines += ["", f"![{caption}](../img/{figure})", "", end]
    page = Path(__file__).resolve().parents[1] / "docs" / "examples" / f"{name}.md"
    replace_section(page, start, end, "\n".join(lines))
