"""The Python call's overhead per frame over the C++ tracker's own time, on a 640 x 480 and a
1920 x 1080 rendered frame tracked from its last pose (the tracked frame, what a loop does).

    PYTHONPATH=build/python python3 python/examples/overhead.py
"""
import statistics
import time

import oalservo


def overhead(width, height, focal, frames=2000):
    camera = oalservo.Camera(px=focal, py=focal, u0=(width - 1) / 2, v0=(height - 1) / 2)
    target = oalservo.Target.builtin("four-line-a3")
    image, _ = oalservo.render(target, camera, width=width, height=height, seed=3)
    tracker = oalservo.TargetPoseTracker(target, camera)
    assert tracker.track(image).status == "ok"
    walls, insides = [], []
    for _ in range(frames):
        start = time.perf_counter()
        frame = tracker.track(image)
        walls.append((time.perf_counter() - start) * 1e6)
        insides.append(frame.time_us)
    wall, inside = statistics.median(walls), statistics.median(insides)
    print(f"{width}x{height}: {wall:.1f} us a call, {inside:.1f} us in the tracker, "
          f"overhead {wall - inside:.1f} us, {1e6 / wall:.0f} frames/s")


overhead(640, 480, 600.0)
overhead(1920, 1080, 1371.0)
