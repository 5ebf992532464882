"""oalservo: the OAL line detector and the four-line target's pose from Python.

Frames are NumPy uint8 arrays, H x W grey (read in place) or H x W x 3 BGR as cv2 gives
them; cMo is a 4 x 4 NumPy array in metres (ViSP's convention). See docs/PYTHON.md.
"""
from ._oalservo import (Camera, Config, DetectorOptions, Line, Options, Target, TargetFrame,
                        TargetPoseTracker, detect, load_config, render)

__all__ = ["Camera", "Config", "DetectorOptions", "Line", "Options", "Target", "TargetFrame",
           "TargetPoseTracker", "detect", "load_config", "render"]
