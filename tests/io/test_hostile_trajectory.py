"""Hostile trajectory CSV files (issue 24, "one safe loader for every file"): what `taut
simulate --trajectory` reads. Each bad file is, through the API, an
:class:`~taut.errors.InvalidTrajectoryError` or :class:`~taut.errors.ScenarioError`
naming the file (its row and column when one cell is at fault), and on the command line
that one line with exit code 2, never a traceback or a silent misreading."""

import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from taut.cli import main
from taut.errors import InvalidTrajectoryError, ScenarioError, TautError
from taut.io.trajectory import (MAX_TRAJECTORY_COLUMNS, MAX_TRAJECTORY_ROWS, load_trajectory,
                                save_trajectory)

ROOT = Path(__file__).parents[2]
SHEET = ROOT / "examples" / "sheet" / "trajectories" / "square4.yaml"
HEADER = "t,x1,y1,x2,y2,x3,y3,x4,y4"
ROWS = ["0.0,0.88,0.85,-0.66,0.5,-0.71,-0.65,0.82,-0.78",
        "0.1,0.88,0.85,-0.66,0.5,-0.70684,-0.65248,0.82,-0.78"]


def good_text():
    return "\n".join([HEADER, *ROWS]) + "\n"


def one_cell(value, row=1, column=3):
    """The good file with cell (row, column) (1-based data row and column) replaced."""
    rows = [r.split(",") for r in ROWS]
    rows[row - 1][column - 1] = value
    return "\n".join([HEADER, *(",".join(r) for r in rows)]) + "\n"


def refused(tmp_path, capsys, content, name="traj.csv"):
    """Load ``content`` through the API and the CLI; returns (API error, CLI line)."""
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif content is not None:
        path.write_text(content, encoding="utf-8", newline="")
    with pytest.raises(TautError) as api_error:
        load_trajectory(path)
    assert isinstance(api_error.value, (InvalidTrajectoryError, ScenarioError))
    assert main(["simulate", str(SHEET), "--trajectory", str(path)]) == 2
    out = capsys.readouterr()
    assert out.out == "" and out.err.count("\n") == 1, out.err
    assert "Traceback" not in out.err
    assert out.err == f"taut: error: {api_error.value}\n"       # the CLI says what the API does
    return api_error.value, out.err


@pytest.mark.parametrize("content, where, words", [
    (one_cell("0.8\x008"), "traj.csv:2", ["column 3 (y1)", "not a number"]),     # NUL byte
    (one_cell("nan"), "traj.csv:2", ["column 3 (y1)", "NaN or infinite"]),
    (one_cell("-inf", row=2, column=8), "traj.csv:3", ["column 8 (x4)", "NaN or infinite"]),
    (one_cell("1e309"), "traj.csv:2", ["column 3 (y1)", "NaN or infinite"]),     # overflows
    (one_cell("1e308", column=4), "traj.csv:2", ["column 4 (x2)", "accepted range"]),
    (one_cell("1e308", row=2, column=1), "traj.csv:3", ["column 1 (t)", "0..86400 s"]),
    (one_cell("-1", column=1), "traj.csv:2", ["column 1 (t)", "0..86400 s"]),
    (one_cell("1_0"), "traj.csv:2", ["column 3 (y1)", "not a number"]),   # float() reads 10
    (one_cell("\u0661"), "traj.csv:2", ["column 3 (y1)", "not a number"]),  # Arabic-Indic 1
    (one_cell(""), "traj.csv:2", ["column 3 (y1)", "not a number"]),
    (good_text() + "0.2,0.88,0.85\n", "traj.csv:4", ["has 3 columns, expected 9"]),  # ragged
    (HEADER + "\n", "traj.csv", ["no data rows"]),                                 # header only
    ("", "traj.csv", ["no data rows"]),
    (good_text().encode() + b"0.2,\xff\xfe,1\n", "traj.csv:4", ["not UTF-8"]),
    (HEADER + "\n" + "0," * MAX_TRAJECTORY_COLUMNS + "0\n", "traj.csv:2",
     [f"at most {MAX_TRAJECTORY_COLUMNS}"]),                                      # one huge row
], ids=["nul", "nan", "-inf", "1e309", "1e308-position", "1e308-time", "negative-time",
        "underscore", "non-ascii-digit", "empty-cell", "ragged", "header-only", "empty",
        "invalid-utf8", "too-many-columns"])
def test_a_bad_trajectory_is_one_line_naming_row_and_column(tmp_path, capsys, content, where,
                                                            words):
    error, line = refused(tmp_path, capsys, content)
    assert error.field.endswith(where), error.field
    assert all(w in error.problem for w in words), error.problem


def test_more_rows_than_the_limit_are_refused_before_parsing(tmp_path, capsys):
    """10^6 rows (23 MB, inside the byte limit): refused by the row limit, which keeps the
    command near 0.2 GB instead of ~0.7 GB and ~25 s of simulation."""
    rows = (f"{k},0,0,1.5,0,0,1.5,1.5,1.5\n" for k in range(10 ** 6))
    error, _ = refused(tmp_path, capsys, HEADER + "\n" + "".join(rows))
    assert f"more than {MAX_TRAJECTORY_ROWS:,} data rows" in error.problem


def test_the_row_limit_is_inclusive(tmp_path):
    """Exactly MAX_TRAJECTORY_ROWS data rows (with a header, a comment, a blank line) load."""
    path = tmp_path / "t.csv"
    body = "".join(f"{k / 10},0,0,1.5,0,0,1.5,1.5,1.5\n" for k in range(MAX_TRAJECTORY_ROWS))
    path.write_text(f"# made by a test\n{HEADER}\n\n{body}")
    assert len(load_trajectory(path)) == MAX_TRAJECTORY_ROWS
    path.write_text(f"{HEADER}\n{body}{MAX_TRAJECTORY_ROWS},0,0,1,0,0,1,1,1\n")
    with pytest.raises(InvalidTrajectoryError, match="data rows"):
        load_trajectory(path)


def test_oversized_file_is_refused_unread(tmp_path, capsys):
    path = tmp_path / "traj.csv"
    with open(path, "wb") as f:
        f.truncate(40 * 2 ** 20)                      # sparse: 40 MiB of NUL bytes
    error, _ = refused(tmp_path, capsys, None)
    assert "at most 32 MiB" in error.problem


def test_a_directory_and_a_fifo_are_named_not_missing(tmp_path, capsys):
    (tmp_path / "traj.csv").mkdir()
    error, _ = refused(tmp_path, capsys, None)
    assert error.problem == "is a directory, not a file"
    if hasattr(os, "mkfifo"):                         # never opened: cannot block
        os.mkfifo(tmp_path / "fifo.csv")
        error, _ = refused(tmp_path, capsys, None, name="fifo.csv")
        assert error.problem.startswith("is not a regular file")


@pytest.mark.parametrize("header", [True, False])
def test_a_byte_order_mark_is_not_part_of_the_first_cell(tmp_path, header):
    """A BOM (spreadsheet exports) used to stick to the first cell: without a header, the
    first data row was then taken for a header and silently dropped."""
    text = good_text() if header else "\n".join(ROWS) + "\n"
    path, plain = tmp_path / "bom.csv", tmp_path / "plain.csv"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode())
    plain.write_text(text)
    a, b = load_trajectory(path), load_trajectory(plain)
    assert len(a) == len(ROWS)
    np.testing.assert_array_equal(a.time, b.time)
    np.testing.assert_array_equal(a.formations, b.formations)


@pytest.mark.parametrize("option, suffix", [("--plot", ".png"), ("--mcap", ".mcap"),
                                            ("--rerun", ".rrd")])
def test_an_output_over_the_trajectory_is_refused(tmp_path, monkeypatch, capsys, option,
                                                  suffix):
    """Every output of `taut simulate` that is another name of its trajectory CSV (a hard
    link with the output's extension) is refused before work, the CSV left as it was."""
    monkeypatch.chdir(tmp_path)
    sheet = tmp_path / "sheet.yaml"
    sheet.write_text(SHEET.read_text() + "units: m\n")
    csv = tmp_path / "traj.csv"
    csv.write_text(good_text())
    os.link(csv, tmp_path / f"out{suffix}")
    assert main(["simulate", "sheet.yaml", "--trajectory", "traj.csv", option,
                 f"out{suffix}"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"'out{suffix}' is also an input" in err, err
    assert csv.read_text() == good_text()


_CELL = st.one_of(st.text(st.characters(blacklist_characters=',"#\r\n'), min_size=1,
                          max_size=8),
                  st.sampled_from(["nan", "inf", "1e999", "0x10", "1_000", "--1", "1e"]))


@settings(max_examples=80, deadline=None)
@given(cell=_CELL, row=st.integers(1, 2), column=st.integers(1, 9))
def test_any_one_bad_cell_is_named_by_row_and_column_or_read_exactly(tmp_path_factory, cell,
                                                                     row, column):
    """One cell replaced by arbitrary text: either the file loads and that cell's value is
    exactly ``float(cell)`` (a plain number), or the error names that row and column."""
    path = tmp_path_factory.mktemp("cell") / "t.csv"
    path.write_text(one_cell(cell, row, column), encoding="utf-8", newline="")
    try:
        traj = load_trajectory(path)
    except InvalidTrajectoryError as exc:
        if "does not increase" in exc.problem:         # a time: the later row is named
            assert column == 1 and exc.field in ("t.csv:2", "t.csv:3"), (exc, cell)
        else:
            assert exc.field == f"t.csv:{row + 1}", (exc, cell)
            assert f"column {column} " in exc.problem, (exc, cell)
        return
    assert cell.strip().isascii() and "_" not in cell
    got = traj.time[row - 1] if column == 1 else \
        traj.formations[row - 1].ravel()[column - 2]
    assert got == float(cell)


def test_save_and_load_round_trip(tmp_path):
    rng = np.random.default_rng(7)
    t = np.cumsum(rng.uniform(0.01, 1, 50))
    formations = rng.uniform(-1e3, 1e3, (50, 5, 2))
    save_trajectory(tmp_path / "t.csv", t, formations)
    back = load_trajectory(tmp_path / "t.csv")
    np.testing.assert_array_equal(back.time, t)
    np.testing.assert_array_equal(back.formations, formations)
