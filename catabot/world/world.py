"""The resolved world of a run: every body, sensor, stream and participant, derived once.

A scenario says what the user asked for; the `World` is what that means, resolved once per
process (and once in the launcher, which refuses what cannot run before anything starts):
start poses placed, the terrain loaded, the traffic planned, vessel models loaded, a row of
`BodyStates` for every body, each sensor's period in ticks, the stream table. Services
receive it built (dm_control's shape: an environment receives built objects) and never
re-derive any of it, so a new kind of body is one change here, not one per service.

Rows: every scenario vessel, then every traffic boat, then every buoy (the scenario's, then
the traffic plan's waypoint buoys). A body's label instance is its row + 1 (0: no body).
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Literal

import numpy as np

from catabot.bus.clock import NS_PER_S, ClockLimits, period_in_ticks
from catabot.bus.keys import Keys
from catabot.bus.messages import CLASS_BUOY, CLASS_VESSEL, BodyStates
from catabot.config.base import ScenarioError
from catabot.config.load import digest
from catabot.config.pose import Velocity
from catabot.config.scenario import (
    ControllerConfig,
    Pose,
    Scenario,
    ScriptStep,
    SensorConfig,
    VesselConfig,
    participants,
    services,
)
from catabot.config.sensors import shard_names
from catabot.config.vessel import VesselModel
from catabot.world import rotations
from catabot.world.environment.current import CurrentField
from catabot.world.placement import (
    BUOY_MODEL,
    Models,
    check_apart,
    check_marks,
    resolve_poses,
    scenario_models,
)
from catabot.world.shapes import ShapeMesh, vessel_mesh
from catabot.world.shards import blocks, sensor_owners
from catabot.world.step_limits import check_step
from catabot.world.streams import Streams
from catabot.world.terrain import Terrain, load_terrain
from catabot.world.traffic_plan import Progress, TrafficPlan, plan_traffic
from catabot.world.waves import WaveField

BodyKind = Literal["vessel", "boat", "buoy"]


@dataclass(frozen=True)
class Body:
    """One rigid body of the run: a scenario vessel, a traffic boat or a buoy."""

    id: str
    kind: BodyKind
    model_ref: str  # the bundled name or path it was loaded from
    model: VesselModel
    pose: Pose  # where it starts, at rest on the calm surface
    row: int  # its row in every `BodyStates`
    script: tuple[ScriptStep, ...] = ()  # in time order (the World sorts it once)
    controller: ControllerConfig | None = None
    velocity: Velocity = field(default_factory=Velocity)  # body frame, at t = 0
    command_timeout_s: float | None = None  # an outside command's hold (catabot/world/orders.py)

    @property
    def instance(self) -> int:
        """Its instance id in LiDAR points, camera masks and boxes."""
        return self.row + 1

    @property
    def label_class(self) -> int:
        return CLASS_BUOY if self.kind == "buoy" else CLASS_VESSEL

    @property
    def script_ns(self) -> list[int]:
        """Each script step's time: physics applies it from the first tick stamped at or
        after it (physics, the recorder and its metrics read the script alike)."""
        return [round(s.t_s * NS_PER_S) for s in self.script]


@dataclass(frozen=True)
class MountedSensor:
    """One sensor on one scenario vessel: its configuration, key and period in ticks."""

    vessel: str
    config: SensorConfig
    key: str
    period: int

    @property
    def seed_name(self) -> str:
        """The name its randomness is seeded with (catabot.world.seeding)."""
        return f"{self.vessel}/{self.config.name}"

    @property
    def params(self) -> Any:
        """The parameters as the type's own model, every default filled in."""
        return self.config.typed_params()


@dataclass(frozen=True, eq=False)  # compared by identity: it holds arrays and meshes
class World:
    scenario: Scenario  # with every start pose resolved
    terrain: Terrain | None
    current: CurrentField  # the water current, its map read once
    bodies: tuple[Body, ...]
    traffic: TrafficPlan
    sensors: tuple[MountedSensor, ...]
    digest: str = ""  # of the scenario as given (config/load.py): the conductor's is the same

    @classmethod
    def resolve(cls, scenario: Scenario, *, progress: Progress | None = None) -> World:
        """Everything a run needs from its scenario; ScenarioError names what cannot run.
        `progress(k, n)` hears of each planned traffic boat (a long plan's progress)."""
        given = digest(scenario)  # as the conductor, which loads the same file, has it
        models = scenario_models(scenario)
        check_step(scenario, models)
        terrain = _terrain(scenario)
        current = CurrentField.from_config(scenario.water.current)
        scenario = resolve_poses(scenario, terrain, models=models)
        check_marks(scenario, terrain, models=models)
        check_apart(scenario, models=models)
        plan = plan_traffic(scenario, terrain, models=models, progress=progress)
        bodies = _bodies(scenario, plan, models)
        keys = Keys(scenario.name)
        sensors = tuple(
            MountedSensor(v.id, s, keys.sensor(v.id, s.name), _period(scenario, v.id, s))
            for v in scenario.vessels
            for s in v.sensors
        )
        return cls(scenario, terrain, current, bodies, plan, sensors, given)

    @cached_property
    def keys(self) -> Keys:
        return Keys(self.scenario.name)

    @cached_property
    def vessels(self) -> tuple[Body, ...]:
        """Scenario vessels, then traffic boats: every body that has thrusters and commands."""
        return tuple(b for b in self.bodies if b.kind != "buoy")

    @cached_property
    def buoys(self) -> tuple[Body, ...]:
        return tuple(b for b in self.bodies if b.kind == "buoy")

    @cached_property
    def body_ids(self) -> tuple[str, ...]:
        """The rows of every `BodyStates`, in order."""
        return tuple(b.id for b in self.bodies)

    @cached_property
    def boat_ids(self) -> tuple[str, ...]:
        """The traffic boats, in `TwistBatch` order."""
        return tuple(b.id for b in self.bodies if b.kind == "boat")

    @cached_property
    def sensor_owners(self) -> dict[str, str]:
        """Sensor stream key -> the sensors process (shard) that produces it."""
        s = self.scenario
        return sensor_owners(self.sensors, s.sensors.shards, s.dt_ns)

    @cached_property
    def shapes(self) -> dict[str, ShapeMesh | None]:
        """Each model's shape as a mesh, by model reference (None: seen as its hull box).
        Read when first asked (mesh files: catabot/world/shapes.py), by the processes that
        cast rays or draw, and by the launcher, which refuses an unreadable mesh file."""
        refs = dict.fromkeys(b.model_ref for b in self.bodies)
        models = {b.model_ref: b.model for b in self.bodies}
        return {ref: vessel_mesh(models[ref], source=ref) for ref in refs}

    @cached_property
    def traffic_blocks(self) -> dict[str, tuple[str, ...]]:
        """Traffic participant -> the boats it guides, in `TwistBatch` order (one block per
        shard of `traffic.shards`; none without traffic)."""
        if not self.boat_ids:
            return {}
        names = shard_names("traffic", self.scenario.traffic.shards)
        return dict(zip(names, blocks(self.boat_ids, len(names)), strict=True))

    def driven_by(self, participants: Collection[str]) -> list[str]:
        """The vessels these participants command, in row order (a controller's vessel, a
        traffic shard's boats): what their drop hands back (clock.policy drop)."""
        boats = {b for name in participants for b in self.traffic_blocks.get(name, ())}
        boats |= {
            v.id for v in self.vessels if v.controller and v.controller.participant in participants
        }
        return [v.id for v in self.vessels if v.id in boats]

    @cached_property
    def streams(self) -> Streams:
        return Streams.of(self)

    @cached_property
    def waves(self) -> WaveField:
        """The scenario's sea at the start (a run-time change: sea_change.py)."""
        return WaveField(self.scenario.water.waves, self.scenario.seed)

    @cached_property
    def clock_limits(self) -> ClockLimits:
        """What participants check every Tick against (catabot/bus/clock.py)."""
        s = self.scenario
        return ClockLimits(s.dt_ns, s.ticks, s.clock.window_ticks, self.digest, s.clock.deadline_s)

    @property
    def participants(self) -> list[str]:
        return participants(self.scenario)

    @property
    def services(self) -> list[str]:
        return services(self.scenario)

    def body(self, body_id: str) -> Body:
        return self._by_id[body_id]

    @cached_property
    def _by_id(self) -> dict[str, Body]:
        return {b.id: b for b in self.bodies}

    def start_states(self) -> BodyStates:
        """Every body at its start pose and velocity (tick -1, t = 0): what physics starts
        from (services/physics/setup.py), velocities in the body frame. In waves `z_m` is
        above the surface at the body's point, roll and pitch are from its slope, and the
        body moves with the water there: one set at z = 0 in a trough fell freely, one under
        a crest was thrown up at 1 g, and a level WAM-V pitched at 12 rad/s^2."""
        n = len(self.bodies)
        p = np.array([(b.pose.x_m, b.pose.y_m, b.pose.z_m) for b in self.bodies]).reshape(n, 3)
        turns = [(b.pose.roll_rad, b.pose.pitch_rad, b.pose.yaw_rad) for b in self.bodies]
        quat = np.array([rotations.from_rpy(*t) for t in turns]).reshape(n, 4)
        linear = np.array([b.velocity.linear for b in self.bodies]).reshape(n, 3)
        if not self.scenario.water.waves.is_calm and n:
            sea = self.waves
            p[:, 2] += sea.height(p[:, 0], p[:, 1])
            quat = rotations.on_slopes(quat, sea.normal(p[:, 0], p[:, 1]))
            water = sea.velocity(p[:, 0], p[:, 1], p[:, 2])  # map frame, at the surface
            linear += np.einsum("nji,nj->ni", rotations.matrices(quat), water)  # R^T: body frame
        angular = np.array([b.velocity.angular for b in self.bodies]).reshape(n, 3)
        zero = np.zeros((n, 3))
        return BodyStates(-1, 0, self.body_ids, p, quat, linear, angular, zero, zero)


def _terrain(scenario: Scenario) -> Terrain | None:
    return load_terrain(scenario.terrain) if scenario.terrain is not None else None


def _bodies(scenario: Scenario, plan: TrafficPlan, models: Models) -> tuple[Body, ...]:
    """Every body in row order; two bodies with one id are refused (they share keys)."""
    model = models.__getitem__
    rows: list[tuple[str, BodyKind, str, Pose, VesselConfig | None]] = []
    for index, v in enumerate(scenario.vessels):
        assert v.pose is not None, "resolve_poses placed every vessel"
        _check_script(v, model(v.model), where=f"vessels.{index}")
        rows.append((v.id, "vessel", v.model, v.pose, v))
    rows += [(b.id, "boat", b.model, b.pose, None) for b in plan.boats]
    buoys = [*scenario.buoys, *plan.buoys]
    rows += [(b.id, "buoy", BUOY_MODEL, Pose(x_m=b.x_m, y_m=b.y_m), None) for b in buoys]
    _unique([r[0] for r in rows])
    fields = {"vessel": "vessels.{}.model", "boat": "traffic.models", "buoy": "buoys"}
    checked: set[str] = set()  # each model once, named by its first body
    for i, (bid, kind, ref, _, _) in enumerate(rows):
        if ref not in checked:
            checked.add(ref)
            where = f"{fields[kind].format(i)} ({bid})"
            _check_floats(where, ref, model(ref), scenario.water.density_kg_m3)
    boats = scenario.traffic.command_timeout_s  # a boat's only scenario part
    return tuple(
        Body(bid, kind, ref, model(ref), pose, row,
             *_scenario_part(config, timeout_s=boats if kind == "boat" else None))
        for row, (bid, kind, ref, pose, config) in enumerate(rows)
    )  # fmt: skip


def _scenario_part(
    config: VesselConfig | None, *, timeout_s: float | None
) -> tuple[tuple[ScriptStep, ...], ControllerConfig | None, Velocity, float | None]:
    """What only a scenario vessel has: its script, its controller, its start velocity, how
    long an outside command holds it (another body: `timeout_s`, a boat's from traffic)."""
    if config is None:
        return (), None, Velocity(), timeout_s
    script = tuple(sorted(config.script, key=lambda s: s.t_s))
    return script, config.controller, config.velocity, config.command_timeout_s


def _check_script(vessel: VesselConfig, model: VesselModel, *, where: str) -> None:
    """A thrust step gives one value per thruster of the vessel's model: physics would
    refuse any other at every tick and the vessel would drift unpowered. Steps may come in
    any order (they are sorted), but one time has one step."""
    count = len(model.thrusters)
    first_at: dict[float, int] = {}  # time: the first step at it
    for k, step in enumerate(vessel.script):
        earlier = first_at.setdefault(step.t_s, k)
        if earlier != k:  # which of the two would rule is a guess: the file's order or not
            raise ScenarioError(f"{where}.script.{k}.t_s: step {earlier} is also at {step.t_s:g} "
                                "s; give each time one step")  # fmt: skip
        if step.thrust is not None and len(step.thrust) != count:
            raise ScenarioError(
                f"{where}.script.{k}.thrust: {len(step.thrust)} value(s), but model "
                f"{vessel.model!r} has {count} thruster(s) (one value each, in [-1, 1])"
            )


def _check_floats(where: str, ref: str, model: VesselModel, density: float) -> None:
    sinks = model.sinks_in(density)
    if sinks:
        raise ScenarioError(f"{where}: vessel model {ref!r} {sinks}")


def _unique(ids: list[str]) -> None:
    seen: set[str] = set()
    for bid in ids:
        if bid in seen:
            raise ScenarioError(
                f"body id {bid!r} is used twice (vessels, traffic boats 'boat_NNN' and buoys "
                "share one namespace: each id names its own keys)"
            )
        seen.add(bid)


def _period(scenario: Scenario, vessel: str, sensor: SensorConfig) -> int:
    return period_in_ticks(sensor.period_ns, scenario.dt_ns, what=f"{vessel}/{sensor.name}")
