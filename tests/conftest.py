import sys
from pathlib import Path

import pytest

# tests/reference.py (the numpy twins) is imported by name from the tests
sys.path.insert(0, str(Path(__file__).parent))

_MEASURED = []


@pytest.fixture
def measured(request):
    """Record a measured value against its closed form; the session ends with
    a table of them (the numbers a closing note or a report quotes)."""

    def record(quantity, value, expected, tolerance):
        error = abs(value - expected) / abs(expected) if expected else abs(value)
        _MEASURED.append((request.node.name, quantity, value, expected, error, tolerance))
        return error

    return record


def pytest_terminal_summary(terminalreporter):
    if not _MEASURED:
        return
    write = terminalreporter.write_line
    terminalreporter.section("measured against closed forms")
    write(f"{'test':58} {'quantity':28} {'measured':>12} {'closed form':>12} {'error':>9} {'tol':>7}")
    for test, quantity, value, expected, error, tol in _MEASURED:
        write(f"{test[:58]:58} {quantity[:28]:28} {value:12.6g} {expected:12.6g} {error:9.2e} {tol:7.0e}")
