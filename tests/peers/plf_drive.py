"""Franka's own client, pylibfranka, drives an FCI controller on
127.0.0.1:1337 (libfranka's fixed port): reads a state, runs a 1 s
joint-position motion of joints 4 and 5 (a raised cosine, 0.1 rad) and
reads the state again. Prints one JSON line: the start and end positions,
the cycles run and the errors the robot reported. Exit status 0 when the
robot ended where commanded (within 1e-3 rad) with no error."""
import json
import math
import sys

import pylibfranka as pf

robot = pf.Robot("127.0.0.1", pf.RealtimeConfig.kIgnore)
start = list(robot.read_once().q)
control = robot.start_joint_position_control(pf.ControllerMode.JointImpedance)
t, cycles, duration, amplitude = 0.0, 0, 1.0, 0.1
while True:
    _, period = control.readOnce()
    t += period.to_sec()
    d = amplitude * (1 - math.cos(math.pi * min(t, duration) / duration)) / 2
    q = list(start)
    q[3] += d
    q[4] += d
    command = pf.JointPositions(q)
    command.motion_finished = t >= duration
    control.writeOnce(command)
    cycles += 1
    if t >= duration:
        break
end = robot.read_once()
error = max(abs(a - b) for a, b in zip(q, end.q))
errors = str(end.current_errors)
print(json.dumps({"start": start, "end": list(end.q), "cycles": cycles,
                  "error": error, "errors": errors}))
sys.exit(0 if error < 1e-3 else 1)
