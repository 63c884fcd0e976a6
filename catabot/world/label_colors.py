"""The label classes' colours, one palette for every picture of them: the viewer's class
images, the SemanticKITTI export's `color_map`, the segmentation export's palette."""

from __future__ import annotations

CLASS_COLORS = {  # RGB by LABEL_CLASSES name (catabot/bus/messages.py)
    "none": (0, 0, 0), "water": (40, 110, 200), "terrain": (120, 170, 90),
    "vessel": (235, 60, 50), "buoy": (250, 200, 30),
}  # fmt: skip
RAIN_COLOR = (255, 0, 255)  # LiDAR rain returns (the paper's Fig. 5 shows them apart)
