"""The long-demonstrations benchmark: runs, refuses what would not fit, resumes."""

from __future__ import annotations

import json

from benchmarks import long_demonstrations as long


def test_runs_records_skips_what_would_not_fit_and_resumes(tmp_path, monkeypatch, capsys):
    out = tmp_path / "runs"
    argv = ["--lengths", "40", "--methods", "rtw", "sk_rtw-dba", "--out", str(out),
            "--figure", str(tmp_path / "plot.png")]  # fmt: skip
    long.main(argv)
    table = capsys.readouterr().out
    records = {p.name: json.loads(p.read_text()) for p in out.iterdir()}
    assert set(records) == {"rtw-40-seed0.json", "sk_rtw-dba-40-seed0.json"}
    for record in records.values():
        assert record["status"] == "ok" and record["seconds"] > 0
        assert 0 <= record["quality"] < 0.05 and record["output_length"] > 0
    assert "| 40 |" in table and (tmp_path / "plot.png").exists()
    # a DBA whose T x T matrix exceeds the memory is not started, nor at longer T
    monkeypatch.setattr(long, "available_bytes", lambda: 1000)
    long.main(["--lengths", "50", "60", "--methods", "aeon-dba", "--out", str(out)])
    assert json.loads((out / "aeon-dba-50-seed0.json").read_text())["status"] == "memory"
    assert not (out / "aeon-dba-60-seed0.json").exists()
    assert "does not fit" in capsys.readouterr().out
    # finished runs are read back, not run again
    monkeypatch.setattr(long, "run_one", lambda *a: (_ for _ in ()).throw(AssertionError))
    long.main(argv)
