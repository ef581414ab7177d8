"""No test reads a wall-clock figure (issue 28): speed is measured by `teamsim bench`, never asserted, because a
loaded machine slows any code down. This reads every test file for the names that carry wall time."""
from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parent
# Keys and clocks that measure the machine, not the simulation.
WALL_CLOCK = {"real_time_factor", "wall_time_s", "wall_s", "decision_times", "perf_counter", "monotonic",
              "process_time"}


def wall_clock_reads(tree: ast.AST) -> list[int]:
    """Lines of asserts that mention a wall-clock name (as a string key, an attribute or a name)."""
    lines = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Assert):
            continue
        for inner in ast.walk(node):
            if _name_of(inner) in WALL_CLOCK:
                lines.append(node.lineno)
    return lines


def _name_of(node: ast.AST) -> str | None:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.Attribute):
        return node.attr
    return node.id if isinstance(node, ast.Name) else None


def test_no_assert_reads_the_wall_clock():
    found = {str(path.relative_to(TESTS)): lines for path in sorted(TESTS.rglob("test_*.py"))
             if (lines := wall_clock_reads(ast.parse(path.read_text())))}
    assert found == {}, f"asserts on wall-clock figures (file: lines): {found}"


def test_the_check_finds_one():
    assert wall_clock_reads(ast.parse('assert summary["real_time_factor"] > 1')) == [1]
    assert wall_clock_reads(ast.parse("assert time.perf_counter() - began < 2")) == [1]
    assert wall_clock_reads(ast.parse('assert summary["sim_time_s"] > 1')) == []
