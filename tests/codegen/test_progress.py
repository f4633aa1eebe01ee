"""The progress line of long steps (issue 30): elapsed time on a terminal only, erased at the end, nothing in logs
or pipes."""

from __future__ import annotations

import io
import threading

from sam_codegen.project.progress import TerminalProgress


class FakeTerminal(io.StringIO):
    def __init__(self) -> None:
        super().__init__()
        self.wrote = threading.Event()

    def isatty(self) -> bool:
        return True

    def write(self, text: str) -> int:
        n = super().write(text)
        self.wrote.set()
        return n


def test_a_terminal_gets_the_label_and_the_elapsed_time_then_the_line_erased() -> None:
    tty = FakeTerminal()
    with TerminalProgress("building ROS package sam_msgs", tty, delay=0.0, interval=0.05) as bar:
        assert tty.wrote.wait(30), "no progress line"
        bar.set("building ROS package sam_msgs: CMake install")
    text = tty.getvalue()
    assert text.startswith("\r\x1b[Kbuilding ROS package sam_msgs ... ") and " s" in text
    assert text.endswith("\r\x1b[K")  # the caller's next line starts clean


def test_a_log_file_or_pipe_gets_nothing() -> None:
    out = io.StringIO()  # not a terminal
    with TerminalProgress("compiling DSDL", out, delay=0.0, interval=0.01) as bar:
        assert not bar.enabled and bar._thread is None  # no ticker at all, so nothing can be written
    assert out.getvalue() == ""


def test_a_short_step_writes_nothing() -> None:
    tty = FakeTerminal()
    with TerminalProgress("compiling DSDL", tty, delay=3600.0):
        pass
    assert tty.getvalue() == ""


def test_the_line_says_the_elapsed_seconds() -> None:
    now = [100.0]
    bar = TerminalProgress("CMake build", io.StringIO(), clock=lambda: now[0])
    with bar:
        now[0] += 12.4
        assert bar.line() == "CMake build ... 12 s"


def test_a_terminal_that_went_away_stops_the_line_not_the_step() -> None:
    class Gone(FakeTerminal):
        def write(self, text: str) -> int:
            self.wrote.set()
            raise OSError("EIO")

    tty = Gone()
    with TerminalProgress("x", tty, delay=0.0, interval=0.01) as bar:  # the failed write raises nothing here
        assert tty.wrote.wait(30)
    assert not bar._shown and not bar._thread.is_alive()
