"""`catabot secure init DIR`: the secure profile's files, for one router and every process.

On an open Zenoh network anyone may publish anything; CataBot's own checks (catabot/bus/
identity.py) catch clients that state who they are, not one that lies. The secure profile
closes that: every process is a client of one router over TLS, logs in with its own user
and password, and the router's access control lets each name publish only its own keys:

| who | may publish (under catabot/<world>/) |
|---|---|
| conductor | clock/tick, clock/end |
| physics, sensors, traffic, recorder | their own lockstep streams, acks and liveliness token |
| a lockstep client (`--client`) | vessel/*/cmd/**, its own ack and token |
| an observer (`--observer`; always `viewer`, for `--view`) | nothing: it subscribes only |

Everyone may subscribe. The files: a test certificate authority and the router's
certificate (openssl), `users.txt`, `router.json5`, and one `<name>.json5` per process and
client (`catabot run --secure DIR`, `--zenoh-config DIR/<name>.json5` for a client).
"""

from __future__ import annotations

import ipaddress
import json
import os
import secrets
import shutil
import subprocess
from pathlib import Path
from typing import Any

from catabot.bus.clock import CONDUCTOR
from catabot.bus.keys import check_name, world_infos
from catabot.bus.session import LEASE_MS, OPEN_TIMEOUT_MS
from catabot.config.sensors import shard_names
from catabot.errors import CataBotError

OWN = {  # keys each process may put besides its ack and its liveliness token
    CONDUCTOR: ["clock/tick", "clock/end"],
    "physics": ["world/states", "world/states/guidance", "vessel/*/state"],
    "sensors": ["sensor/**"],
    "traffic": ["world/cmd/twist"],
    "recorder": [],
}
COMMANDS = ["vessel/*/cmd/**"]
READ = ["declare_subscriber", "declare_liveliness_subscriber", "liveliness_query"]
# everyone may read the settings (`catabot get`) and the world (a stack's Client.connect)
ASK = ["catabot/*/config/settings", world_infos()]
SET = ["catabot/*/config/set"]  # commanding clients may change them (`catabot set`)


class SecureError(CataBotError, RuntimeError):
    """The secure profile's files could not be made."""


def own_keys(sensor_shards: int = 1, traffic_shards: int = 1) -> dict[str, list[str]]:
    """Each CataBot process's keys; a shard may put any of its service's (consumers believe
    a sample only from the shard that owns its stream: catabot/bus/inbox.py)."""
    for what, n in (("sensors", sensor_shards), ("traffic", traffic_shards)):
        if not 1 <= n <= 64:
            raise SecureError(f"{what} shards {n}: use 1 to 64 ({what}.shards)")
    sensors = {n: OWN["sensors"] for n in shard_names("sensors", sensor_shards)}
    traffic = {n: ["world/cmd/twist/*"] for n in shard_names("traffic", traffic_shards)}
    return {**OWN, **sensors, **(traffic if traffic_shards > 1 else {})}


def init(
    folder: Path, *, clients: list[str], observers: list[str], host: str = "localhost",
    port: int = 7447, sensor_shards: int = 1, traffic_shards: int = 1,
) -> list[Path]:  # fmt: skip
    """Every file of the profile in `folder`; the paths written."""
    observers = [*observers, *(["viewer"] if "viewer" not in observers else [])]  # --view
    own = own_keys(sensor_shards, traffic_shards)
    names = [*own, *(check_name("client", c) for c in clients),
             *(check_name("observer", o) for o in observers)]  # fmt: skip
    if len(set(names)) != len(names):
        raise SecureError(f"names must differ from each other and from {', '.join(own)}")
    folder = folder.resolve()  # the config files name the certificates from anywhere
    if (folder / "users.txt").exists():  # a second init replaced every login and the CA
        raise SecureError(
            f"{folder} already holds a profile: a new one would change its CA "
            "and every login (give another folder, or remove this one first)"
        )
    folder.mkdir(parents=True, exist_ok=True)
    umask = os.umask(0o077)  # every file private from its creation, never readable a moment
    try:
        _certificates(folder, host)
        users = {name: secrets.token_urlsafe(18) for name in ["router", *names]}
        (folder / "users.txt").write_text("".join(f"{u}:{p}\n" for u, p in users.items()))
        endpoint = f"tls/{host}:{port}"
        router = _router(folder, endpoint, users, clients, observers, own)
        pki = [folder / f for f in ("ca.pem", "ca.key", "router.pem", "router.key")]
        written = [*pki, folder / "users.txt", _write(folder / "router.json5", router)]
        for name in names:
            config = _session(folder, endpoint, name, users)
            written.append(_write(folder / f"{name}.json5", config))
    finally:
        os.umask(umask)
    for public in ("ca.pem", "router.pem"):  # the certificates every machine reads
        (folder / public).chmod(0o644)
    return written


def _is_address(host: str) -> bool:
    """Whether `host` is an IPv4 or IPv6 address: a certificate names it as `IP:`, and one
    made with `DNS:10.9.0.1` was refused by every client connecting to 10.9.0.1."""
    try:
        ipaddress.ip_address(host.strip("[]"))
    except ValueError:
        return False
    return True


def _certificates(folder: Path, host: str) -> None:
    """A test CA and the router's certificate (for a real deployment, your own PKI)."""
    if shutil.which("openssl") is None:
        raise SecureError("openssl is needed to make the test certificates (apt install openssl)")
    ext = folder / "router.ext"
    name = f"IP:{host.strip('[]')}" if _is_address(host) else f"DNS:{host}"  # no DNS name
    ext.write_text(f"subjectAltName={name},DNS:localhost,IP:127.0.0.1\n")
    steps = [
        ["req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", "ca.key", "-out", "ca.pem",
         "-days", "3650", "-subj", "/CN=catabot-test-ca"],
        ["req", "-newkey", "rsa:2048", "-nodes", "-keyout", "router.key", "-out", "router.csr",
         "-subj", f"/CN={host}"],
        ["x509", "-req", "-in", "router.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
         "-CAcreateserial", "-out", "router.pem", "-days", "3650", "-extfile", "router.ext"],
    ]  # fmt: skip
    for step in steps:
        done = subprocess.run(["openssl", *step], cwd=folder, capture_output=True, text=True)
        if done.returncode != 0:
            raise SecureError(f"openssl {step[0]}: {done.stderr.strip()[-300:]}")
    for scratch in ("router.ext", "router.csr", "ca.srl"):
        (folder / scratch).unlink(missing_ok=True)


def _router(
    folder: Path, endpoint: str, users: dict[str, str], clients: list[str], observers: list[str],
    own: dict[str, list[str]],
) -> dict[str, Any]:  # fmt: skip
    return {
        "mode": "router",
        "listen": {"endpoints": [endpoint]},
        "scouting": {"multicast": {"enabled": False}},
        "transport": {
            "link": {
                "tls": {
                    "listen_private_key": str(folder / "router.key"),
                    "listen_certificate": str(folder / "router.pem"),
                },
                "tx": {"lease": LEASE_MS, "keep_alive": 4},
            },
            "auth": {
                "usrpwd": {
                    "user": "router",
                    "password": users["router"],
                    "dictionary_file": str(folder / "users.txt"),
                }
            },
        },
        "access_control": _acl(own, clients, observers),
    }


def _acl(own: dict[str, list[str]], clients: list[str], observers: list[str]) -> dict[str, Any]:
    """Default deny; everyone may subscribe and receive; each writer its own keys."""
    writers = [*own, *clients]
    everyone = [*writers, *observers]
    rules: list[dict[str, Any]] = [
        _rule("read", READ, ["ingress", "egress"], ["catabot/**"]),
        _rule("receive", ["put", "delete", "liveliness_token", "reply"], ["egress"],
              ["catabot/**"]),
        _rule("ask", ["query"], ["ingress"], ASK),
        _rule("set", ["query"], ["ingress"], SET),
        _rule("desk", ["declare_queryable", "query", "reply"], ["ingress", "egress"],
              ["catabot/*/config/**", world_infos()]),
    ]  # fmt: skip
    policies = [
        {"rules": ["read", "receive", "ask"], "subjects": ["everyone"]},
        {"rules": ["desk"], "subjects": [CONDUCTOR]},
    ]
    subjects = [{"id": "everyone", "usernames": everyone}]
    if clients:
        subjects.append({"id": "clients", "usernames": clients})
        policies.append({"rules": ["set"], "subjects": ["clients"]})
    for name in writers:
        keys = [*own.get(name, COMMANDS if name in clients else []), f"clock/ack/{name}"]
        rules.append(_rule(f"{name}-puts", ["put"], ["ingress"], [f"catabot/*/{k}" for k in keys]))
        rules.append(_rule(f"{name}-token", ["liveliness_token"], ["ingress", "egress"],
                           [f"catabot/*/live/{name}/*"]))  # fmt: skip
        subjects.append({"id": name, "usernames": [name]})
        policies.append({"rules": [f"{name}-puts", f"{name}-token"], "subjects": [name]})
    return {"enabled": True, "default_permission": "deny", "rules": rules,
            "subjects": subjects, "policies": policies}  # fmt: skip


def _rule(rule_id: str, messages: list[str], flows: list[str], keys: list[str]) -> dict[str, Any]:
    return {"id": rule_id, "permission": "allow", "messages": messages, "flows": flows,
            "key_exprs": keys}  # fmt: skip


def _session(folder: Path, endpoint: str, name: str, users: dict[str, str]) -> dict[str, Any]:
    return {
        "mode": "client",
        "connect": {"endpoints": [endpoint]},
        "scouting": {"multicast": {"enabled": False}},
        "transport": {
            "unicast": {"open_timeout": OPEN_TIMEOUT_MS},  # session.py `_embedded` says why
            "link": {
                "tls": {"root_ca_certificate": str(folder / "ca.pem")},
                "tx": {"lease": LEASE_MS, "keep_alive": 4},
            },
            "auth": {"usrpwd": {"user": name, "password": users[name]}},
        },
    }


def _write(path: Path, config: dict[str, Any]) -> Path:
    path.write_text(json.dumps(config, indent=2) + "\n")  # it holds a password: init's umask
    return path


def router_endpoint(folder: Path) -> str:
    """The endpoint the profile's router listens on (what `catabot run --secure` connects to)."""
    try:
        config = json.loads((folder / "router.json5").read_text())
        return str(config["listen"]["endpoints"][0])
    except (OSError, ValueError, KeyError, IndexError) as exc:
        raise SecureError(
            f"{folder}: no secure profile here ({exc}); see catabot secure init"
        ) from None
