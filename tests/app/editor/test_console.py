"""The Python console: typed lines run in the namespace, output and errors show, history recalls lines."""

import sys

import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QFontDatabase
from pytestqt.qtbot import QtBot

from app.editor.docks.console import PythonConsole


@pytest.fixture
def namespace() -> dict:
    return {"rw": object()}


@pytest.fixture
def console(qtbot: QtBot, namespace: dict) -> PythonConsole:
    console = PythonConsole(namespace)
    qtbot.addWidget(console)
    console.show()
    return console


def enter(qtbot: QtBot, console: PythonConsole, line: str) -> None:
    """Types ``line`` in the input and presses Enter, as a user does."""
    qtbot.keyClicks(console.input, line)
    qtbot.keyClick(console.input, Qt.Key.Key_Return)


def test_typed_assignment_runs_in_the_namespace(qtbot: QtBot, console: PythonConsole, namespace: dict) -> None:
    enter(qtbot, console, "x = 6 * 7")
    assert namespace["x"] == 42
    assert console.input.text() == ""
    assert ">>> x = 6 * 7" in console.output.toPlainText()


def test_the_namespace_given_is_the_one_code_sees(console: PythonConsole, namespace: dict) -> None:
    assert console.run("found = rw") is False
    assert namespace["found"] is namespace["rw"]


def test_print_and_expression_results_show_in_the_output(qtbot: QtBot, console: PythonConsole) -> None:
    console.run("x = 6 * 7")
    enter(qtbot, console, "print(x)")
    enter(qtbot, console, "x + 1")
    assert console.output.toPlainText().splitlines()[-4:] == [">>> print(x)", "42", ">>> x + 1", "43"]


def test_multi_line_block_waits_for_an_empty_line(console: PythonConsole, namespace: dict) -> None:
    assert console.run("total = 0") is False
    assert console.run("for i in range(4):") is True
    assert console.prompt.text() == "..."
    assert console.run("    total += i") is True
    assert "total" in namespace and namespace["total"] == 0  # not run yet
    assert console.run("") is False
    assert console.prompt.text() == ">>>"
    assert namespace["total"] == 6
    assert "...     total += i" in console.output.toPlainText()


def test_multi_line_block_typed_by_the_user(qtbot: QtBot, console: PythonConsole) -> None:
    enter(qtbot, console, "for i in range(3):")
    assert console.prompt.text() == "..."
    enter(qtbot, console, "    print(i * 10)")
    enter(qtbot, console, "")
    assert console.prompt.text() == ">>>"
    assert console.output.toPlainText().splitlines()[-3:] == ["0", "10", "20"]


def test_an_exception_shows_its_traceback_and_the_console_keeps_working(
    qtbot: QtBot, console: PythonConsole, namespace: dict
) -> None:
    enter(qtbot, console, "1/0")
    text = console.output.toPlainText()
    assert "Traceback (most recent call last)" in text
    assert "ZeroDivisionError: division by zero" in text
    assert console.prompt.text() == ">>>"
    enter(qtbot, console, "y = 1")
    assert namespace["y"] == 1


def test_a_syntax_error_shows_and_resets_the_prompt(console: PythonConsole, namespace: dict) -> None:
    assert console.run("x = = 1") is False
    assert "SyntaxError" in console.output.toPlainText()
    assert console.run("x = 1") is False
    assert namespace["x"] == 1


def test_system_exit_does_not_exit(qtbot: QtBot, console: PythonConsole, namespace: dict) -> None:
    assert console.run("raise SystemExit(1)") is False  # directly first: an escaping SystemExit fails the test
    assert console.output.toPlainText().count("SystemExit ignored") == 1
    enter(qtbot, console, "raise SystemExit")
    assert console.output.toPlainText().count("SystemExit ignored") == 2
    console.run("for i in range(2):")
    assert console.run("    exit()") is True
    assert console.run("") is False  # the block raising SystemExit leaves no pending input
    assert console.prompt.text() == ">>>"
    console.run("z = 3")
    assert namespace["z"] == 3


def test_up_and_down_recall_the_history(qtbot: QtBot, console: PythonConsole) -> None:
    enter(qtbot, console, "a = 1")
    enter(qtbot, console, "b = 2")
    qtbot.keyClick(console.input, Qt.Key.Key_Up)
    assert console.input.text() == "b = 2"
    qtbot.keyClick(console.input, Qt.Key.Key_Up)
    assert console.input.text() == "a = 1"
    qtbot.keyClick(console.input, Qt.Key.Key_Up)
    assert console.input.text() == "a = 1"  # stays on the oldest line
    qtbot.keyClick(console.input, Qt.Key.Key_Down)
    assert console.input.text() == "b = 2"
    qtbot.keyClick(console.input, Qt.Key.Key_Down)
    assert console.input.text() == ""  # past the newest line: an empty input


def test_a_recalled_line_runs_again(qtbot: QtBot, console: PythonConsole, namespace: dict) -> None:
    namespace["n"] = 0
    enter(qtbot, console, "n += 1")
    qtbot.keyClick(console.input, Qt.Key.Key_Up)
    qtbot.keyClick(console.input, Qt.Key.Key_Return)
    assert namespace["n"] == 2


def test_empty_history_does_nothing(qtbot: QtBot, console: PythonConsole) -> None:
    qtbot.keyClicks(console.input, "draft")
    qtbot.keyClick(console.input, Qt.Key.Key_Up)
    assert console.input.text() == "draft"
    qtbot.keyClick(console.input, Qt.Key.Key_Down)
    assert console.input.text() == "draft"


def test_standard_streams_are_redirected_during_a_run_and_restored_after(
    console: PythonConsole, namespace: dict
) -> None:
    stdout, stderr = sys.stdout, sys.stderr
    namespace["outside"] = (stdout, stderr)
    console.run("import sys; print('redirected', sys.stdout is not outside[0], sys.stderr is not outside[1])")
    assert "redirected True True" in console.output.toPlainText()
    for line in ("1/0", "raise SystemExit(2)", "x = = 1"):
        console.run(line)
        assert sys.stdout is stdout and sys.stderr is stderr


def test_output_is_read_only_and_monospace(console: PythonConsole) -> None:
    assert console.output.isReadOnly()
    fixed = QFontDatabase.systemFont(QFontDatabase.SystemFont.FixedFont)
    assert console.output.font().family() == fixed.family()
    assert console.input.font().family() == fixed.family()
