"""Write a mesh-free MuJoCo model of the FR3 for franka-sim.

franka-sim loads Menagerie's FR3 from GitHub on first use, which a test
machine cannot reach; its wheel bundles the FR3's URDF, whose meshes it
does not ship. This keeps that URDF's kinematics and inertias, drops
visuals and collisions, and gives the joints the armature Menagerie's
model has: without it the simulator's joint servo makes the light
seventh link unstable at 1 kHz.

Usage: python fr3_mjcf.py OUT.xml
"""

import importlib.resources
import sys
import xml.etree.ElementTree as ET

import mujoco

urdf = ET.fromstring(
    (importlib.resources.files("franka_sim") / "models" / "fr3.urdf").read_text()
)
for link in urdf.iter("link"):
    for tag in ("visual", "collision"):
        for element in link.findall(tag):
            link.remove(element)
compiler = ET.SubElement(ET.SubElement(urdf, "mujoco"), "compiler")
compiler.set("discardvisual", "true")
compiler.set("fusestatic", "true")
compiled = mujoco.MjModel.from_xml_string(ET.tostring(urdf, encoding="unicode"))
mujoco.mj_saveLastXML(sys.argv[1], compiled)
model = ET.parse(sys.argv[1])
for joint in model.iter("joint"):
    joint.set("armature", "0.1")
model.write(sys.argv[1])
