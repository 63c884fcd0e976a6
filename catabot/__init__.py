"""CataBot: co-simulation of autonomous surface vehicles over Zenoh, in lockstep."""

__version__ = "0.1.0"
