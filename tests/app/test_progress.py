"""Progress display: plain lines without a terminal, a redrawn bar with one."""
import io

from damper.run.progress import Progress


def test_plain_lines_when_not_a_terminal():
    err, out = io.StringIO(), io.StringIO()
    p = Progress(2, stream=err, out=out)              # StringIO is not a terminal
    p.start("a", "compute")
    p.echo("result line")
    p.finish("a", 1.5)
    p.close()
    assert err.getvalue() == "[1/2] a: compute ...\n[1/2] a: done in 1.50 s\n"
    assert out.getvalue() == "result line\n"


def test_live_bar_redraws_in_place():
    err, out = io.StringIO(), io.StringIO()
    p = Progress(4, stream=err, out=out, live=True)
    p.start("tangential:x", "compute")
    p.finish("tangential:x", 0.1)
    p.close()
    text = err.getvalue()
    assert "\n" not in text and "\r\033[K" in text
    assert "tangential:x (compute)" in text and "[######..................] 1/4" in text


def test_live_bar_shows_the_steps_inside_a_stage():
    err = io.StringIO()
    p = Progress(1, stream=err, out=io.StringIO(), live=True)
    p.start("condense:c:zx", "compute")
    p.step(3, 7, "assembly body 2")
    p.close()
    assert "condense:c:zx (compute)" in err.getvalue() and "3/7 assembly body 2" in err.getvalue()


def test_a_stage_note_is_a_line_on_the_progress_stream_above_the_bar():
    """A stage's own line (optimal_load's cost estimate) goes where the commands print theirs,
    standard error, on a line of its own: the bar is cleared first and redrawn under it."""
    for live in (False, True):
        err, out = io.StringIO(), io.StringIO()
        p = Progress(1, stream=err, out=out, live=live)
        p.start("optimal_load", "compute")
        p.note("about 1234 residual evaluations")
        p.close()
        assert out.getvalue() == ""
        before, line, after = err.getvalue().partition("about 1234 residual evaluations\n")
        assert line and (not live or (before.endswith("\r\033[K") and "optimal_load (compute)" in after))
