"""A stand-in for ros2_control's joint_trajectory_controller, in rclpy.

Serves control_msgs/action/FollowJointTrajectory on
/CONTROLLER/follow_joint_trajectory and publishes sensor_msgs/JointState
on /joint_states (stamped, 100 Hz). An accepted goal is executed in real
time: the joints follow the trajectory's points, linearly interpolated,
with feedback at 50 Hz. Like the real controller, a goal whose joint names
are not the controller's (as a set, any order) ends with INVALID_JOINTS.

--mode:
  ok       execute and succeed (error code 0)
  reject   reject every goal
  abort    abort half-way through with PATH_TOLERANCE_VIOLATED (-4)
  silent   stop publishing /joint_states once a goal is accepted
  mute     never publish /joint_states
  stale    once a goal is accepted, keep publishing one stamp

One JSON line on stdout for each goal and how it ended; exits after
--lifetime seconds or on SIGTERM.
"""

import argparse
import json
import signal
import sys
import threading
import time

import rclpy
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from sensor_msgs.msg import JointState
from control_msgs.action import FollowJointTrajectory as FJT


def say(**event):
    print(json.dumps(event), flush=True)


def at(points, t):
    """The positions at time t, linearly between the points."""
    times = [p.time_from_start.sec + p.time_from_start.nanosec * 1e-9 for p in points]
    if t <= times[0]:
        return list(points[0].positions)
    for (ta, a), (tb, b) in zip(zip(times, points), zip(times[1:], points[1:])):
        if t <= tb:
            s = (t - ta) / (tb - ta) if tb > ta else 1.0
            return [x + (y - x) * s for x, y in zip(a.positions, b.positions)]
    return list(points[-1].positions)


class FakeJtc(Node):
    def __init__(self, args):
        super().__init__("fake_jtc")
        self.mode = args.mode
        self.joints = args.joints.split(",")
        self.q = [float(x) for x in args.start.split(",")]
        if len(self.q) != len(self.joints):
            sys.exit("--start needs one position per joint")
        self.lock = threading.Lock()
        self.publishing = self.mode != "mute"
        self.frozen = None
        self.states = self.create_publisher(JointState, "/joint_states", 10)
        self.timer = self.create_timer(0.01, self.publish_state)
        self.server = ActionServer(
            self,
            FJT,
            f"{args.controller}/follow_joint_trajectory",
            self.execute,
            goal_callback=self.on_goal,
            cancel_callback=lambda _: CancelResponse.ACCEPT,
            callback_group=ReentrantCallbackGroup(),
        )

    def publish_state(self):
        if not self.publishing:
            return
        m = JointState()
        m.header.stamp = self.frozen or self.get_clock().now().to_msg()
        m.name = self.joints
        with self.lock:
            m.position = list(self.q)
        self.states.publish(m)

    def on_goal(self, goal):
        t = goal.trajectory
        say(event="goal", joints=list(t.joint_names), points=len(t.points),
            start=list(t.points[0].positions) if t.points else [])
        if self.mode == "reject":
            say(event="rejected")
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def end(self, handle, how, code, text=""):
        getattr(handle, how)()
        say(event=how, error_code=code)
        r = FJT.Result()
        r.error_code = code
        r.error_string = text
        return r

    def execute(self, handle):
        goal = handle.request.trajectory
        if sorted(goal.joint_names) != sorted(self.joints) or not goal.points:
            return self.end(handle, "abort", FJT.Result.INVALID_JOINTS,
                            "joints are not the controller's")
        order = [list(goal.joint_names).index(j) for j in self.joints]
        if self.mode == "silent":
            self.publishing = False
        if self.mode == "stale":
            self.frozen = self.get_clock().now().to_msg()
        end = goal.points[-1].time_from_start
        duration = end.sec + end.nanosec * 1e-9
        t0 = time.monotonic()
        while True:
            t = time.monotonic() - t0
            if handle.is_cancel_requested:
                return self.end(handle, "canceled", 0, "canceled")
            if self.mode == "abort" and t >= duration / 2:
                return self.end(handle, "abort", FJT.Result.PATH_TOLERANCE_VIOLATED,
                                "fake_jtc: half-way")
            q = at(goal.points, t)
            with self.lock:
                self.q = [q[i] for i in order]
            fb = FJT.Feedback()
            fb.joint_names = self.joints
            fb.desired.positions = list(self.q)
            fb.actual.positions = list(self.q)
            fb.error.positions = [0.0] * len(self.joints)
            handle.publish_feedback(fb)
            if t >= duration:
                return self.end(handle, "succeed", FJT.Result.SUCCESSFUL)
            time.sleep(0.02)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--controller", default="/arm_controller")
    p.add_argument("--mode", default="ok",
                   choices=["ok", "reject", "abort", "silent", "mute", "stale"])
    p.add_argument("--joints", default="a1,a2,a3,a4,a5,a6,a7")
    p.add_argument("--start", default="0,0,0,0,0,0,0")
    p.add_argument("--lifetime", type=float, default=60.0)
    args = p.parse_args()
    rclpy.init()
    node = FakeJtc(args)
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    signal.signal(signal.SIGTERM, lambda *_: executor.shutdown(timeout_sec=0))
    say(event="ready")
    deadline = time.monotonic() + args.lifetime
    try:
        while rclpy.ok() and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.1)
    except (ExternalShutdownException, KeyboardInterrupt):
        pass
    node.destroy_timer(node.timer)
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
