"""Live pose of the printed A3 sheet from a webcam, with OpenCV's cv2 (Debian's python3-opencv).

    PYTHONPATH=build/python python3 python/examples/webcam_pose.py camera.yaml [device]
"""
import sys

import cv2
import oalservo

camera = oalservo.Camera.from_file(sys.argv[1])  # ViSP XML, OpenCV YAML or ROS camera_info
tracker = oalservo.TargetPoseTracker(oalservo.Target.builtin("four-line-a3"), camera)
capture = cv2.VideoCapture(int(sys.argv[2]) if len(sys.argv) > 2 else 0, cv2.CAP_V4L2)
capture.set(cv2.CAP_PROP_FOURCC, cv2.VideoWriter_fourcc(*"MJPG"))
capture.set(cv2.CAP_PROP_FRAME_WIDTH, 1280)
capture.set(cv2.CAP_PROP_FRAME_HEIGHT, 720)
while True:
    ok, bgr = capture.read()
    if not ok:
        break
    frame = tracker.track(bgr)  # BGR as cv2 gives it; a grey array is read in place
    if frame.status == "ok":
        print(f"t = {frame.cMo[:3, 3]} m  ({frame.time_us:.0f} us)")
    else:
        print(frame.status, frame.message)
