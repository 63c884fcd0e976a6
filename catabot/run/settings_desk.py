"""The conductor's settings desk: a Zenoh queryable on `catabot/<world>/config/**`.

`config/settings` answers the settings as JSON, now and once the changes scheduled apply
(what `catabot get` prints);
`config/set` with a JSON payload `{"key": ..., "value": ...}` checks the change with the
scenario's own models (catabot/config/live.py) and schedules it on the clock
(catabot/bus/settings.py), answering the tick it takes effect at. Anything else, and any
change refused, gets an error reply naming what is allowed; refusals are counted like any
refused sample (rejections.py) and never touch the run. The callback runs on a Zenoh thread
and never blocks: the schedule's lock is held for a dictionary update.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable, Mapping
from typing import Any

import zenoh

from catabot.bus.keys import Keys
from catabot.bus.rejections import Rejected, Rejections
from catabot.bus.settings import Schedule, SettingsError
from catabot.config import live
from catabot.config.scenario import Scenario
from catabot.run.advice import tell

log = logging.getLogger("catabot.run.settings")
MAX_QUERY_BYTES = 4096  # a key and a value: anything bigger is not a setting


class QueryRefused(Exception):
    """A query the desk answers with an error (the message is the reply)."""


class SettingsDesk:
    def __init__(
        self,
        session: zenoh.Session,
        keys: Keys,
        scenario: Scenario,
        schedule: Schedule,
        *,
        planned: Callable[[], Mapping[str, str]] = dict,
    ) -> None:
        """`planned()`: each traffic boat's behaviour as the plan drew it, once the world
        is resolved (WorldInfoDesk; until then a drawn boat's is "as planned")."""
        self.keys, self.scenario, self.schedule = keys, scenario, schedule
        self.planned = planned
        self.rejections = Rejections(log, "settings")
        self.answered = 0
        self._initial = live.initial_values(scenario)
        self._queryable = session.declare_queryable(keys.configs(), self._on_query)

    def _on_query(self, query: zenoh.Query) -> None:
        key = str(query.key_expr)
        try:
            answer = self._answer(key, query)
        except (QueryRefused, live.SettingError, SettingsError) as exc:
            self.rejections.add(key, Rejected("setting refused", str(exc)))
            _reply_err(query, str(exc))
            return
        except Exception:  # a bug must not kill the queryable: the run goes on
            log.exception("settings query on %s failed", key)
            _reply_err(query, "the settings desk failed on this query (see log/conductor.log)")
            return
        self.answered += 1
        settings = zenoh.KeyExpr(key).intersects(zenoh.KeyExpr(self.keys.config("settings")))
        where = self.keys.config("settings" if settings else "set")  # `catabot/**` asked too
        try:
            query.reply(where, json.dumps(answer))
        except zenoh.ZError as exc:  # the asker gave up; nothing to do
            log.warning("could not answer a settings query: %s", exc)

    def _answer(self, key: str, query: zenoh.Query) -> dict[str, Any]:
        """What a query on `key` gets: the settings, or a change's effect tick."""
        if zenoh.KeyExpr(key).intersects(zenoh.KeyExpr(self.keys.config("settings"))):
            return self.in_force()  # `catabot/*/config/settings` too: how worlds are found
        if key == self.keys.config("set"):  # a change goes to one world, named
            return self._set(_payload(query))
        raise QueryRefused(
            f"no such settings query {key!r}; ask {self.keys.config('settings')} (get) or "
            f'{self.keys.config("set")} (set, with a JSON payload {{"key": ..., "value": ...}})'
        )

    def _set(self, request: Any) -> dict[str, Any]:
        if not isinstance(request, dict) or set(request) != {"key", "value"}:
            raise QueryRefused('a set takes a JSON object {"key": ..., "value": ...}')
        text = live.check(self.scenario, request["key"], request["value"])
        change = self.schedule.propose(request["key"], text)
        t_s = change.tick * self.scenario.dt_ns / 1e9
        tell(log, f"setting {change.key} = {text} from tick {change.tick} (t = {t_s:g} s)")
        return {"key": change.key, "value": change.decoded, "tick": change.tick, "t_s": t_s}

    def in_force(self) -> dict[str, Any]:
        """Every key's value once the changes scheduled so far apply, and where it stands."""
        values, planned = dict(self._initial), self.planned()
        specs = live.keys_of(self.scenario)
        for key, spec in specs.items():  # a drawn boat's behaviour, once the plan is known
            if spec.kind == "behaviour" and values[key] == live.AS_PLANNED:
                values[key] = planned.get(spec.owner, live.AS_PLANNED)
        changes, granted = self.schedule.in_force(), self.schedule.granted
        now = dict(values)
        for change in changes:
            values[change.key] = change.decoded
            if change.tick <= granted:
                now[change.key] = change.decoded
        entries = [live.entry(c, self.scenario.dt_ns) | {"tick": c.tick} for c in changes]
        return {
            "world": self.keys.world,
            "granted": granted,
            "dt_ns": self.scenario.dt_ns,
            "settings": values,  # once every change scheduled so far has applied
            "now": now,  # at the last tick granted: a timeline's later entries not yet
            "allowed": {key: spec.allowed for key, spec in specs.items()},
            "changes": entries,
            "due": [e for e in entries if e["tick"] > granted],  # what `now` leaves out
        }

    def close(self) -> None:
        self._queryable.undeclare()


def _payload(query: zenoh.Query) -> Any:
    payload = query.payload
    data = payload.to_bytes() if payload is not None else b""
    if len(data) > MAX_QUERY_BYTES:
        raise QueryRefused(f"a set of {len(data)} bytes; at most {MAX_QUERY_BYTES}")
    try:
        return json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise QueryRefused(f"a set's payload is not JSON: {exc}") from None


def _reply_err(query: zenoh.Query, message: str) -> None:
    try:
        query.reply_err(json.dumps({"error": message}))
    except zenoh.ZError as exc:
        log.warning("could not answer a settings query: %s", exc)
