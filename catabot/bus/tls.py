"""The certificate and key files a Zenoh config file names, checked before Zenoh opens it:
a missing `ca.pem` was reported as a failed TLS handshake or login, never named."""

from __future__ import annotations

import json
from pathlib import Path

import zenoh

TLS_FILES = ("root_ca_certificate", "connect_certificate", "connect_private_key",
             "listen_certificate", "listen_private_key")  # fmt: skip


def missing_file(config: zenoh.Config) -> str:
    """'' when every TLS file the config names exists, else which one does not."""
    for name in TLS_FILES:
        file = json.loads(config.get_json(f"transport/link/tls/{name}"))
        if isinstance(file, str) and not Path(file).is_file():
            return f"its transport/link/tls/{name} {file} does not exist"
    return ""
