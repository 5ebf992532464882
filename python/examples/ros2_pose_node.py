"""A ROS 2 node: subscribes to an image topic, publishes the sheet's pose as a PoseStamped.

ROS 2 is not packaged for Debian bookworm: this example is checked for syntax only.

    ros2 run ... (or) python3 ros2_pose_node.py --ros-args -p camera_file:=camera.yaml
"""
import numpy as np
import rclpy
from geometry_msgs.msg import PoseStamped
from rclpy.node import Node
from scipy.spatial.transform import Rotation
from sensor_msgs.msg import Image

import oalservo


class SheetPoseNode(Node):
    def __init__(self):
        super().__init__("oalservo_pose")
        camera_file = self.declare_parameter("camera_file", "camera.yaml").value
        self.tracker = oalservo.TargetPoseTracker(
            oalservo.Target.builtin("four-line-a3"), oalservo.Camera.from_file(camera_file))
        self.publisher = self.create_publisher(PoseStamped, "target_pose", 10)
        self.create_subscription(Image, "image_raw", self.on_image, 10)

    def on_image(self, message):
        if message.encoding not in ("mono8", "bgr8"):
            self.get_logger().warning(f"encoding {message.encoding}: mono8 or bgr8 expected")
            return
        channels = 1 if message.encoding == "mono8" else 3
        image = np.frombuffer(message.data, dtype=np.uint8).reshape(
            message.height, message.step // channels, channels)[:, :message.width].squeeze()
        frame = self.tracker.track(image)
        if frame.status != "ok":
            return
        pose = PoseStamped()
        pose.header = message.header
        pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = frame.cMo[:3, 3]
        x, y, z, w = Rotation.from_matrix(frame.cMo[:3, :3]).as_quat()
        pose.pose.orientation.x, pose.pose.orientation.y = x, y
        pose.pose.orientation.z, pose.pose.orientation.w = z, w
        self.publisher.publish(pose)


def main():
    rclpy.init()
    rclpy.spin(SheetPoseNode())


if __name__ == "__main__":
    main()
