"""The end of `catabot run`: a summary, `log/run.json`, and the exit code.

Exit codes: 0 completed, 1 a fault (the failing participant is named), 130 interrupted.
Wall-clock figures go to `log/` only: the rest of the run folder must not depend on
wall-clock time (DESIGN.md §7).
"""

from __future__ import annotations

import contextlib
import json
import signal
import sys
from collections.abc import Mapping
from pathlib import Path

from catabot.bus.clock import CONDUCTOR, ender_of
from catabot.config.scenario import Scenario
from catabot.run.metrics_summary import metrics_lines
from catabot.run.provenance import provenance
from catabot.run.service import EXIT_CLOCK
from catabot.run.supervisor import PROGRAM_REAP_S
from catabot.run.usage import MEMORY, memory_mb, read_usage


def describe_exit(code: int | None) -> str:
    if code is None:
        return "still running"
    if code < 0:
        return f"killed by {signal.Signals(-code).name}"
    return f"exit code {code}"


def _memory(
    run_dir: Path, services: Mapping[str, object], result: Mapping[str, object]
) -> dict[str, dict[str, float]]:
    """Each memory figure (usage.MEMORY) of every process of the run and of the whole
    stack, MiB: the launcher's own measured now, the conductor's from its result line."""
    own = memory_mb()
    return {field: _processes(run_dir, services, result, own, field) for field in MEMORY}


def _processes(
    run_dir: Path,
    services: Mapping[str, object],
    result: Mapping[str, object],
    own: Mapping[str, float],
    field: str,
) -> dict[str, float]:
    """A process that did not report `field` is left out (a crash; no smaps_rollup)."""
    out = {"launcher": own[field]} if field in own else {}
    with contextlib.suppress(KeyError, TypeError, ValueError):  # a conductor that died: none
        out["conductor"] = float(result[field])  # type: ignore[arg-type]
    out |= read_usage(run_dir, services, field)
    return out | {"total": round(sum(out.values()), 1)}


def _rejected(
    run_dir: Path, services: Mapping[str, object], result: Mapping[str, object]
) -> dict[str, dict[str, int]]:
    """Inputs each process refused, by reason (log/<process>.rejected.json). The conductor's
    come in its result line; they are written to its file here, so every process has one
    where its console line says (it named a file that was never written)."""
    out: dict[str, dict[str, int]] = {}
    conductor = result.get("rejected")
    if isinstance(conductor, dict) and conductor:
        totals = {str(k): int(v) for k, v in sorted(conductor.items())}
        with contextlib.suppress(OSError):
            (run_dir / "log" / f"{CONDUCTOR}.rejected.json").write_text(
                json.dumps(totals, indent=2) + "\n"
            )
    for name in [CONDUCTOR, *services]:
        path = run_dir / "log" / f"{name}.rejected.json"
        with contextlib.suppress(OSError, ValueError):
            out[name] = {str(k): int(v) for k, v in json.loads(path.read_text()).items()}
    return out


def _print_rejected(rejected: Mapping[str, Mapping[str, int]], run_dir: Path) -> None:
    if not rejected:
        return
    parts = [
        f"{name} {sum(r.values())} ({', '.join(f'{k} {v}' for k, v in r.items())})"
        for name, r in rejected.items()
    ]
    print(f"refused inputs: {'; '.join(parts)} (see {run_dir / 'log'})", file=sys.stderr)


def summarise(
    scenario: Scenario,
    run_dir: Path,
    result: Mapping[str, object],
    conductor_code: int | None,
    service_codes: Mapping[str, int | None],
    *,
    stopped: set[str] | frozenset[str] = frozenset(),
    lingered: set[str] | frozenset[str] = frozenset(),
    after_fault: set[str] | frozenset[str] = frozenset(),
    progress: Mapping[str, object] | None = None,
) -> int:
    """`stopped`: services stopped before they joined an interrupted run; `lingered`:
    programs still running after a clean end; `after_fault`: services still running after a
    fault had ended the run (SIGTERM, exit 143): none of them is a failure of its own.
    `progress`: the conductor's last progress line, what a killed one leaves (its summary
    said "0 ticks" of 800 run)."""
    ticks = int(result.get("ticks_done", 0))  # type: ignore[call-overload]
    wall = float(result.get("wall_s", 0.0))  # type: ignore[arg-type]
    if not result and progress:
        ticks = int(progress["tick"]) + 1  # type: ignore[call-overload]
        wall = ticks / float(progress["ticks_per_s"])  # type: ignore[arg-type]
    sim_s = ticks * scenario.dt_ns / 1e9
    error = str(result.get("error", "") or "")
    interrupted = result.get("reason") == "interrupted" or conductor_code == 130
    unjoined: set[str] = set()  # an interrupted start: stopped while still starting, or
    if interrupted and not ticks:  # ended on seeing the stopped conductor go first
        unjoined = set(stopped) | {n for n, c in service_codes.items() if c == EXIT_CLOCK}
    dropped = dict(result.get("why_dropped") or {})  # type: ignore[call-overload]
    spared = unjoined | set(lingered) | set(dropped) | set(after_fault)  # not failures
    failed = {n: c for n, c in service_codes.items() if c not in (0, None) and n not in spared}
    if not result:
        error = error or f"the conductor ended without a result ({describe_exit(conductor_code)})"
    elif not error and failed:
        error = "service(s) failed: " + ", ".join(failed)
    record = {
        "ticks": ticks,
        "sim_s": sim_s,
        "wall_s": wall,
        "error": error,
        "reason": result.get("reason") or _reason(error, interrupted=interrupted),
        "services": dict(service_codes),
        "cpu_s": read_usage(run_dir, service_codes, "cpu_s"),
        **_memory(run_dir, service_codes, result),
        "rejected": _rejected(run_dir, service_codes, result),
        "dropped": dropped,
        **provenance(scenario),
    }
    try:
        (run_dir / "log" / "run.json").write_text(json.dumps(record, indent=2) + "\n")
    except OSError as exc:
        print(f"catabot run: cannot write {run_dir / 'log' / 'run.json'}: {exc.strerror}",
              file=sys.stderr)  # fmt: skip
    rtf = sim_s / wall if wall > 0 else 0.0
    print(
        f"{ticks} ticks, {sim_s:.2f} s simulated in {wall:.2f} s "
        f"({ticks / max(wall, 1e-9):.0f} ticks/s, real-time factor {rtf:.1f})"
    )
    order = [v.id for v in scenario.vessels]
    for line in metrics_lines(run_dir, order) if ticks else []:  # no tick stepped: nothing measured
        print(line)
    for name in (n for n, c in service_codes.items() if c == 0 and n.startswith("export-")):
        print(f"  {name}: {_last_line(run_dir, name)}")  # what it wrote, as the CLI says it
    for name in sorted(unjoined):
        print(f"  {name}: stopped by catabot run before it joined", file=sys.stderr)
    for name, why in dropped.items():
        print(f"  {name}: dropped, the run went on without it (clock.policy drop): {why}",
              file=sys.stderr)  # fmt: skip
    for name in sorted(after_fault):
        print(f"  {name}: stopped by catabot run after the fault", file=sys.stderr)
    for name in sorted(lingered):
        print(
            f"  {name}: still running {PROGRAM_REAP_S:g} s after the run ended, so stopped "
            "(a controller program should exit once run_lockstep returns)",
            file=sys.stderr,
        )
    for name, code in failed.items():
        log = run_dir / "log" / f"{name}.log"
        said = f": {_last_line(run_dir, name)}" if name.startswith("export-") else ""
        print(f"  {name}: {describe_exit(code)}{said} (see {log})", file=sys.stderr)
    _print_rejected(record["rejected"], run_dir)
    if ender_of(str(record["reason"])) is not None:  # a participant's end (Ack.end)
        print(f"run {record['reason']}")
    print(f"run folder: {run_dir}")
    if error:
        print(f"run failed: {error}", file=sys.stderr)
        return 1
    if interrupted:
        print("run interrupted; " + ("files are complete up to the last tick" if record["ticks"]
              else "before its first tick: nothing was recorded"), file=sys.stderr)  # fmt: skip
        return 130
    return 0


def _last_line(run_dir: Path, name: str) -> str:
    """A companion program's last line in its log: its one-line answer (catabot/run/answer.py)."""
    try:
        lines = (run_dir / "log" / f"{name}.log").read_text(errors="replace").splitlines()
    except OSError:
        return "(no log)"
    return next((x.strip() for x in reversed(lines) if x.strip()), "(empty log)")[:300]


def _reason(error: str, *, interrupted: bool) -> str:
    """How a run ended when the conductor said nothing (it failed, or was stopped, before
    its first tick): run.json's `reason` is never empty for a script to test."""
    return "interrupted" if interrupted else "fault" if error else "completed"
