"""A ``--scheduler`` address where no Dask scheduler answers is bad input: exit 2, not a crash."""

import socket
from pathlib import Path

from sandwich.cli import EXIT_BAD_INPUT, main

TINY = Path(__file__).resolve().parent / "tiny.toml"


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_no_scheduler_at_the_address_is_refused_with_the_address(tmp_path, capsys):
    address = f"tcp://127.0.0.1:{_free_port()}"
    code = main(["study", str(TINY), "--out", str(tmp_path / "out"), "--scheduler", address,
                 "--quiet"])
    err = capsys.readouterr().err
    assert code == EXIT_BAD_INPUT
    assert "--scheduler" in err and address in err and "Traceback" not in err
    assert "internal error" not in err
