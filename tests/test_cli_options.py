"""The command line refuses what the server would refuse, in the same one-line sentence."""

from __future__ import annotations

import pytest

from airtable import cli
from airtable.net.server import validate_server_options


@pytest.mark.parametrize(
    "flags, options",
    [
        (["--max-clients", "5000"], {"max_clients": 5000}),
        (["--snapshot-hz", "2000"], {"snapshot_hz": 2000.0}),
    ],
)
def test_the_command_line_refuses_what_the_server_would(flags, options, capsys) -> None:
    with pytest.raises(ValueError) as refused:
        validate_server_options(**options)
    with pytest.raises(SystemExit) as exited:
        cli.main([*flags, "--headless", "--seconds", "0.05"])
    assert exited.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].endswith(str(refused.value).rstrip("."))
    assert "Traceback" not in "\n".join(err)


def test_without_a_server_the_server_options_are_not_checked(capsys) -> None:
    assert cli.main(["--no-server", "--max-clients", "5000", "--headless", "--seconds", "0.05", "--demo", "1"]) == 0
