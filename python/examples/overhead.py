"""A webcam-style loop from Python against the tracker's own rate: a sequence of rendered
frames of the A3 sheet sliding across the view (50 frames, played 20 times), each tracked from
the last pose, at 640 x 480 and 1920 x 1080. Prints the time of a call from Python, the
tracker's own time inside it (what a C++ loop would spend), the overhead and both rates.

    PYTHONPATH=build/python python3 python/examples/overhead.py
"""
import statistics
import time

import oalservo


def loop(width, height, focal, frames=50, rounds=20):
    camera = oalservo.Camera(px=focal, py=focal, u0=(width - 1) / 2, v0=(height - 1) / 2)
    target = oalservo.Target.builtin("four-line-a3")
    _, start = oalservo.render(target, camera, width=width, height=height, seed=3)
    sequence = []
    for k in range(frames):
        cMo = start.copy()
        cMo[0, 3] += 0.001 * k  # 1 mm a frame
        sequence.append(oalservo.render(target, camera, width=width, height=height, seed=3,
                                        cMo=cMo)[0])
    tracker = oalservo.TargetPoseTracker(target, camera)
    calls, insides, ok = [], [], 0
    for _ in range(rounds):
        tracker.reset()
        for image in sequence:
            begin = time.perf_counter()
            frame = tracker.track(image)
            calls.append((time.perf_counter() - begin) * 1e6)
            insides.append(frame.time_us)
            ok += frame.status == "ok"
    call, inside = statistics.median(calls), statistics.median(insides)
    print(f"{width}x{height}: {call:.1f} us a call from Python, {inside:.1f} us in the tracker, "
          f"overhead {call - inside:.1f} us; {1e6 / call:.0f} frames/s from Python against "
          f"{1e6 / inside:.0f} ({100 * (inside / call - 1):+.1f} %); {ok} of {len(calls)} ok")


loop(640, 480, 600.0)
loop(1920, 1080, 1371.0)
