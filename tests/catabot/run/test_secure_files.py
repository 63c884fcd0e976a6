"""The secure profile's files: secrets private from their creation, public certificates
readable, and a second `init` into a profile refused (it replaced the CA and every login)."""

from __future__ import annotations

import stat
from pathlib import Path

import pytest

from catabot.run import secure


def test_secrets_are_private_and_certificates_public(tmp_path: Path) -> None:
    written = secure.init(tmp_path / "p", clients=["stack"], observers=[])
    modes = {p.name: stat.S_IMODE(p.stat().st_mode) for p in written}
    assert modes["ca.pem"] == modes["router.pem"] == 0o644
    private = {n: m for n, m in modes.items() if not n.endswith(".pem")}
    assert {"users.txt", "ca.key", "router.key", "stack.json5"} <= set(private)
    assert set(private.values()) == {0o600}


def test_a_second_init_into_a_profile_is_refused(tmp_path: Path) -> None:
    secure.init(tmp_path / "p", clients=[], observers=[])
    before = (tmp_path / "p" / "users.txt").read_text()
    with pytest.raises(secure.SecureError, match="already holds a profile"):
        secure.init(tmp_path / "p", clients=[], observers=[])
    assert (tmp_path / "p" / "users.txt").read_text() == before
