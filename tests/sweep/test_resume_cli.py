"""`taut sweep run --resume` through the real command (issue 24, "Sweeps"): a truncated
chunk used to make ``--resume`` fail with an ``ArrowInvalid`` traceback. The library path
is tested in tests/sweep/test_sweep_safety.py; here the installed ``taut`` runs as its own
process with the flag, as a user would type it."""

import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytest.importorskip("pyarrow")

from taut.sweep import read_results  # noqa: E402

ROOT = Path(__file__).parents[2]
TAUT = Path(sys.executable).with_name("taut")


def taut(*args):
    proc = subprocess.run([str(TAUT), *map(str, args)], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)
    return proc.returncode, proc.stdout, proc.stderr


@pytest.mark.slow                       # ~20 s loaded: three `taut` processes
def test_resume_flag_recomputes_a_truncated_chunk(tmp_path, same_rows):
    sweep = tmp_path / "s.yaml"
    sweep.write_text(textwrap.dedent(f"""\
        task: fk_stability_map
        base: {ROOT / 'examples/sheet/example2_r2_r4_353mm.yaml'}
        chunk_size: 3
        parameters: {{scale: {{range: [0.6, 1.0], num: 8}}}}
        """))
    clean, out = tmp_path / "clean", tmp_path / "out"
    for folder in (clean, out):
        code, stdout, stderr = taut("sweep", "run", sweep, "--out", folder, "--workers", "0")
        assert code == 0, stderr
        assert "(3 chunks computed, 0 reused" in stdout
    chunk = out / "chunks" / "chunk-0000001.parquet"
    chunk.write_bytes(chunk.read_bytes()[:100])                     # truncated
    code, stdout, stderr = taut("sweep", "run", sweep, "--out", out, "--workers", "0",
                                "--resume")
    assert code == 0, stderr
    assert "Traceback" not in stderr and "ArrowInvalid" not in stderr, stderr
    # the summary line says one chunk was recomputed and the two intact ones reused, and
    # stderr names it and why
    assert re.search(r"^8 rows -> .* \(1 chunks computed, 2 reused, ", stdout, re.M), stdout
    assert "taut: sweep: chunks/chunk-0000001.parquet recomputed (truncated)\n" in stderr, \
        stderr
    assert len(chunk.read_bytes()) > 100
    same_rows(read_results(out)[0], read_results(clean)[0])
