"""The radar PPI lives in the library now (catabot/ros2/ppi.py: the gateway publishes it as
a ROS 2 image too); dataset.py, which writes its PNGs, imports it from here."""

from catabot.ros2.ppi import Ppi

__all__ = ["Ppi"]
