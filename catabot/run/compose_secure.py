"""The secure variant of a compose file: a `catabot secure init` profile in containers.

The profile's config files name its certificates by absolute path (catabot/run/secure.py),
so every file is mounted at the path it has on the host (`CATABOT_SECURE`, default the
profile's folder). Each container gets only what it needs, and what holds a password as a
compose secret: a process its own login (`<name>.json5`, mounted as a secret) and the CA's
certificate; the router its config (its own password), the users' file and its key as
secrets, its certificate as a volume. Nobody else sees the CA's key or another's password.

Inside the compose network the processes reach the router by the host name the profile was
made for (`catabot secure init DIR --host NAME`: the name in its TLS certificate), which the
router's container carries as a network alias; clients outside use the same name.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from catabot.errors import CataBotError

LOOPBACK = {"localhost", "127.0.0.1", "::1", "[::1]"}
ROUTER_SECRETS = {"router-config": "router.json5", "router-users": "users.txt",
                  "router-key": "router.key"}  # fmt: skip


class SecureComposeError(CataBotError, ValueError):
    """The secure profile cannot be used in containers as it is."""


@dataclass(frozen=True)
class Profile:
    folder: Path  # where the profile's files say they are (absolute)
    endpoint: str  # tls/<host>:<port>, as the router listens and the clients connect
    host: str
    port: int

    @property
    def var(self) -> str:
        """The folder, on the host and in every container."""
        return f"${{CATABOT_SECURE:-{self.folder}}}"

    def login(self, name: str) -> str:
        return f"{self.var}/{name}.json5"

    @property
    def router_config(self) -> str:
        return f"{self.var}/router.json5"

    def mounts(self, name: str) -> dict[str, Any]:
        """A process's login (a secret) and the CA certificate it checks the router with."""
        ca = f"{self.var}/ca.pem"
        return {"secrets": [{"source": f"{name}-login", "target": self.login(name)}],
                "volumes": [f"{ca}:{ca}:ro"]}  # fmt: skip

    def router_mounts(self) -> dict[str, Any]:
        """Its config, users and key; and, for its health check, the observer 'viewer''s
        login and the CA's certificate (compose.py `_router_probe`)."""
        pem, ca = f"{self.var}/router.pem", f"{self.var}/ca.pem"
        secrets = [{"source": s, "target": f"{self.var}/{f}"} for s, f in ROUTER_SECRETS.items()]
        secrets.append({"source": "viewer-login", "target": self.login("viewer")})
        networks = {} if self.host == "router" else {"default": {"aliases": [self.host]}}
        return {"secrets": secrets, "volumes": [f"{pem}:{pem}:ro", f"{ca}:{ca}:ro"],
                **({"networks": networks} if networks else {})}  # fmt: skip

    def secrets(self, names: list[str]) -> dict[str, Any]:
        files = {**ROUTER_SECRETS, **{f"{n}-login": f"{n}.json5" for n in names}}
        return {s: {"file": f"{self.var}/{f}"} for s, f in files.items()}


def profile(folder: Path, needed: list[str], *, ros: bool) -> Profile:
    """The profile in `folder`, checked: it has a login for every process, its files still
    name this folder, and its router has a name the containers can reach it by."""
    if ros:
        raise SecureComposeError(
            "the ROS gateway is not in the secure profile (its keys are ROS topic names): "
            "run a ROS scenario on a trusted network, without --secure"
        )
    folder = folder.resolve()
    try:
        config = json.loads((folder / "router.json5").read_text())
        endpoint = str(config["listen"]["endpoints"][0])
        key = Path(config["transport"]["link"]["tls"]["listen_private_key"])
    except (OSError, ValueError, KeyError, IndexError, TypeError) as exc:
        raise SecureComposeError(
            f"{folder}: no secure profile here ({exc}); make one with catabot secure init"
        ) from None
    if key.parent != folder:
        raise SecureComposeError(
            f"{folder}: the profile was made in {key.parent} and its files name that folder; "
            "make it again where it is (catabot secure init)"
        )
    missing = [n for n in needed if not (folder / f"{n}.json5").is_file()]
    if missing:
        raise SecureComposeError(
            f"{folder}: no login for {', '.join(missing)} (catabot secure init)"
        )
    host, _, port = endpoint.partition("/")[2].rpartition(":")
    if host in LOOPBACK:
        raise SecureComposeError(
            f"{folder}: the router is {endpoint}, which in a container is the container itself; "
            "make the profile with --host NAME (NAME: how clients reach this machine; the "
            "containers reach the router by it too), e.g. catabot secure init DIR --host router"
        )
    return Profile(folder, endpoint, host, int(port))
