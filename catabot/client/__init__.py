"""The client API: what an autonomy stack imports to drive a running CataBot world.

Connect, discover the world by a query (no scenario file), read states and sensors as typed
messages with NumPy arrays, send Thrust/Twist/Waypoints, and run the stack free or joined
to the lockstep (deterministic). See the README, "Plugging in your autonomy stack".
"""

from catabot.bus.clock import EndRun
from catabot.bus.messages import (
    BodyStates,
    CameraFrame,
    End,
    GpsFix,
    ImuSample,
    LidarScan,
    RadarSweep,
    VesselState,
)
from catabot.client.client import Client, add_stack_args
from catabot.client.commands import Command, Thrust, Twist, Waypoints
from catabot.client.errors import (
    ClientError,
    CommandError,
    NoData,
    NotAParticipant,
    NotItsVessel,
    RunEnded,
    SeveralVessels,
    SeveralWorlds,
    SimulatorNotFound,
    TooLate,
    UnknownSensor,
    UnknownVessel,
    WrongRate,
)
from catabot.client.info import Buoy, ControllerInfo, SensorInfo, VesselInfo, WorldInfo
from catabot.client.lockstep import Joined, Observation
from catabot.client.vessel import Sensor, Vessel

__all__ = [
    "BodyStates",
    "Buoy",
    "CameraFrame",
    "Client",
    "ClientError",
    "Command",
    "CommandError",
    "ControllerInfo",
    "End",
    "EndRun",
    "GpsFix",
    "ImuSample",
    "Joined",
    "LidarScan",
    "NoData",
    "NotAParticipant",
    "NotItsVessel",
    "Observation",
    "RadarSweep",
    "RunEnded",
    "Sensor",
    "SensorInfo",
    "SeveralVessels",
    "SeveralWorlds",
    "SimulatorNotFound",
    "Thrust",
    "TooLate",
    "Twist",
    "UnknownSensor",
    "UnknownVessel",
    "Vessel",
    "VesselInfo",
    "VesselState",
    "Waypoints",
    "WorldInfo",
    "WrongRate",
    "add_stack_args",
]
