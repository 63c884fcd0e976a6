"""The viewer's layout, set once so the first view is useful without a click.

Left: the 3D world following the first scenario vessel (terrain, water, every body with its
trail over the last 30 s, the LiDAR cloud, the radar sector), the speed, heading and thrust
series below it. Right: each camera with its segmentation and boxes overlaid, each radar's
north-up minimap showing the last antenna turn (the paper's PPI), then tabs for the IMU, the
LiDAR returns, the closest approach, the real-time factor and the metrics table. Every view
reads the `sim_time` timeline.
"""

from __future__ import annotations

from typing import Any

import rerun.blueprint as rrb

from catabot.config.sensors import RadarParams
from catabot.world.world import World
from services.viewer import paths

TIMELINE = "sim_time"
TRAIL_WINDOW_S = 30.0


def _last(seconds: float) -> rrb.VisibleTimeRange:
    return rrb.VisibleTimeRange(
        TIMELINE,
        start=rrb.TimeRangeBoundary.cursor_relative(seconds=-seconds),
        end=rrb.TimeRangeBoundary.cursor_relative(),
    )


def _world_view(world: World) -> rrb.Spatial3DView:
    trails = rrb.VisibleTimeRanges([_last(TRAIL_WINDOW_S)])
    eye = None
    if world.scenario.vessels:
        ego = world.body(world.scenario.vessels[0].id)
        x, y = ego.pose.x_m, ego.pose.y_m
        eye = rrb.EyeControls3D(
            position=(x - 70.0, y - 70.0, 45.0),
            look_target=(x, y, 0.0),
            eye_up=(0.0, 0.0, 1.0),
            tracking_entity=paths.vessel(ego.id),
        )
    return rrb.Spatial3DView(
        origin=paths.WORLD,
        name="World",
        overrides={paths.TRAILS: trails},
        eye_controls=eye,
        background=(12, 20, 32),
    )


def _sensor_views(world: World) -> list[Any]:
    views: list[Any] = []
    for s in world.sensors:
        name = f"{s.vessel}.{s.config.name}"
        if s.config.type == "camera":
            views.append(rrb.Spatial2DView(origin=paths.sensor(s.vessel, s.config.name), name=name))
        elif s.config.type == "radar":
            params = s.params
            assert isinstance(params, RadarParams)
            views.append(
                rrb.Spatial2DView(
                    origin=paths.minimap(s.vessel, s.config.name),
                    name=f"{name} (PPI, north up)",
                    time_ranges=_last(params.rotation_period_s),
                    background=(0, 0, 0),
                )
            )
    return views


def _series(quantity: str, name: str) -> rrb.TimeSeriesView:
    return rrb.TimeSeriesView(origin=f"series/{quantity}", name=name)


def blueprint(world: World, *, live: bool) -> rrb.Blueprint:
    below = rrb.Horizontal(
        _series("speed", "speed [m/s]"),
        _series("heading", "heading [deg]"),
        rrb.Tabs(_series("thrust", "thrust"), _series("setpoint", "twist set-points")),
    )
    left = rrb.Vertical(_world_view(world), below, row_shares=[5, 2])
    tabs = [
        _series("imu_accel", "IMU accel"),
        _series("imu_gyro", "IMU gyro"),
        _series("lidar", "LiDAR returns"),
        rrb.TimeSeriesView(origin=paths.CLOSEST, name="closest approach [m]"),
        rrb.TextDocumentView(origin=paths.METRICS, name="metrics"),
    ]
    if live:
        tabs.insert(0, rrb.TimeSeriesView(origin=paths.RTF, name="real-time factor"))
    right = rrb.Vertical(*_sensor_views(world), rrb.Tabs(*tabs))
    return rrb.Blueprint(
        rrb.Horizontal(left, right, column_shares=[3, 2]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(timeline=TIMELINE, state="collapsed"),
    )
