"""The Python module as a user calls it: a rendered A3 frame tracked to its true pose, a
sequence followed, bad arrays refused, the frame read in place, two trackers on two threads."""
import threading

import numpy as np
import pytest

import oalservo

CAMERA = oalservo.Camera(px=600.0, py=600.0, u0=319.5, v0=239.5)
A3 = oalservo.Target.builtin("four-line-a3")


def pose_error(cMo, truth):
    """Translation error over the distance, and the rotation error in degrees."""
    translation = np.linalg.norm(cMo[:3, 3] - truth[:3, 3]) / np.linalg.norm(truth[:3, 3])
    relative = cMo[:3, :3].T @ truth[:3, :3]
    angle = np.degrees(np.arccos(np.clip((np.trace(relative) - 1.0) / 2.0, -1.0, 1.0)))
    return translation, angle


def test_a_rendered_frame_is_tracked_to_its_true_pose():
    image, truth = oalservo.render(A3, CAMERA, seed=3)
    assert image.dtype == np.uint8 and image.shape == (480, 640)
    frame = oalservo.TargetPoseTracker(A3, CAMERA).track(image)
    assert frame.status == "ok", frame.message
    assert frame.cMo.shape == (4, 4)
    translation, rotation = pose_error(frame.cMo, truth)
    assert translation < 0.005 and rotation < 0.5
    assert len(frame.corners_px) == 4 and all(index >= 0 for index in frame.lines)


def test_a_bgr_frame_gives_the_same_pose_as_its_grey():
    image, _ = oalservo.render(A3, CAMERA, seed=4)
    bgr = np.dstack([image, image, image])
    grey = oalservo.TargetPoseTracker(A3, CAMERA).track(image)
    colour = oalservo.TargetPoseTracker(A3, CAMERA).track(bgr)
    assert grey.status == colour.status == "ok"
    assert np.allclose(grey.cMo, colour.cMo, atol=1e-9)


def test_a_sequence_is_followed_and_reset_forgets_it():
    tracker = oalservo.TargetPoseTracker(A3, CAMERA)
    image, truth = oalservo.render(A3, CAMERA, seed=5)
    for step in range(5):
        moved = truth.copy()
        moved[0, 3] += 0.002 * step  # the sheet slides 2 mm a frame
        frame_image, frame_truth = oalservo.render(A3, CAMERA, seed=5, cMo=moved)
        frame = tracker.track(frame_image)
        assert frame.status == "ok", frame.message
        assert pose_error(frame.cMo, frame_truth)[0] < 0.005
    tracker.reset()
    assert tracker.track(image).status == "ok"


def test_bad_arrays_are_refused_with_a_value_error():
    tracker = oalservo.TargetPoseTracker(A3, CAMERA)
    with pytest.raises(ValueError, match="uint8"):
        tracker.track(np.zeros((480, 640), dtype=np.float32))
    with pytest.raises(ValueError, match="H x W grey or H x W x 3 BGR"):
        tracker.track(np.zeros((480, 640, 4), dtype=np.uint8))
    with pytest.raises(ValueError, match="contiguous"):
        tracker.track(np.zeros((480, 1280), dtype=np.uint8)[:, ::2])
    with pytest.raises(ValueError, match="smaller than 16"):
        oalservo.detect(np.zeros((8, 8), dtype=np.uint8))
    with pytest.raises(RuntimeError, match="does not exist"):
        oalservo.Camera.from_file("/no/such/camera.yaml")


def test_the_frame_is_read_in_place():
    # A crop of a larger array (rows padded) is read without a copy: writing into the parent
    # changes what the next track sees.
    image, _ = oalservo.render(A3, CAMERA, seed=3)
    parent = np.zeros((480, 700), dtype=np.uint8)
    parent[:, :640] = image
    crop = parent[:, :640]
    assert not crop.flags["C_CONTIGUOUS"]
    tracker = oalservo.TargetPoseTracker(A3, CAMERA)
    assert tracker.track(crop).status == "ok"
    parent[:, :640] = 200  # blank, in place
    tracker.reset()
    assert tracker.track(crop).status != "ok"


def test_two_trackers_on_two_threads():
    images = [oalservo.render(A3, CAMERA, seed=seed) for seed in (6, 7)]
    results = [None, None]

    def run(index):
        tracker = oalservo.TargetPoseTracker(A3, CAMERA)
        results[index] = [tracker.track(images[index][0]).status for _ in range(20)]

    threads = [threading.Thread(target=run, args=(index,)) for index in (0, 1)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert results[0] == ["ok"] * 20 and results[1] == ["ok"] * 20


def test_detect_finds_the_sheets_lines():
    image, _ = oalservo.render(A3, CAMERA, seed=3)
    lines = oalservo.detect(image)
    assert len(lines) >= 4
    assert all(0 <= line.theta_rad < 2 * np.pi + 1e-9 for line in lines)


def test_the_examples_are_valid_python(tmp_path):
    # The webcam example needs a camera and cv2, the ROS 2 node needs rclpy (not packaged for
    # Debian bookworm): both are compiled, not run.
    import os
    import py_compile

    examples = os.path.join(os.environ.get("OAL_SOURCE_DIR", "."), "python", "examples")
    for name in ("webcam_pose.py", "ros2_pose_node.py", "overhead.py"):
        py_compile.compile(os.path.join(examples, name), cfile=str(tmp_path / (name + "c")),
                           doraise=True)


def source_path(*parts):
    import os

    return os.path.join(os.environ.get("OAL_SOURCE_DIR", "."), *parts)


def test_options_are_plain_objects_checked_as_the_yaml_sections():
    options = oalservo.Options()
    assert options.detector.step_px == 5 and options.detector.polarity == "dark"
    options.detector.step_px = 4
    options.detector.check()
    image, _ = oalservo.render(A3, CAMERA, seed=3)
    assert oalservo.TargetPoseTracker(A3, CAMERA, options).track(image).status == "ok"
    assert len(oalservo.detect(image, options)) >= 4
    options.detector.step_px = 0
    with pytest.raises(ValueError, match="step_px"):
        options.check()
    with pytest.raises(ValueError, match="step_px"):
        oalservo.TargetPoseTracker(A3, CAMERA, options)
    with pytest.raises(ValueError, match="dark"):
        options.detector.polarity = "purple"


def test_a_configuration_file_gives_its_target_and_options_and_its_errors(tmp_path):
    config = oalservo.load_config(source_path("config", "four-line-a4.yaml"))
    assert config.target.name == "four-line-a4"
    assert oalservo.Target.from_yaml(source_path("config", "four-line-a4.yaml")).name == "four-line-a4"
    edges = oalservo.load_config(source_path("config", "visp_line_edges.yaml"))
    assert edges.options.detector.polarity == "edges"
    bad = tmp_path / "bad.yaml"
    bad.write_text("detector:\n  step_px: 0\n")
    with pytest.raises(Exception, match="bad.yaml:2"):
        oalservo.load_config(str(bad))
