"""A franky-sim server for the Franka backend's tests: the FR3 with its hand in MuJoCo,
a plate of square holes (four wall boxes each) and square pegs standing on the table,
built from a small JSON description; the simulator fixes of
``/work/shared/notes/franky-sim.md`` done at run time (no franky-sim file edited):

- the external wrench in the state (``O_F_ext_hat_K``, ``K_F_ext_hat_K``): what a
  force/torque sensor at the flange (the hand body's origin) measures, the gravity of the
  hand and of the load (``set_load``) removed, about the end effector;
- the measured pose recomputed from the joints (franky-sim reports the commanded one);
- joint 7's damping and the fingers' gain.

``python -m tests.franka.franky_sim_harness SCENE.json`` prints ``ready HOST`` when it
serves, then runs until killed. The scene: ``{"holes": [[x, y, side], ...], "top_z": z,
"depth": d, "pegs": [[x, y, side, length, mass], ...]}`` [m, kg]."""

from __future__ import annotations

import json
import sys
import xml.etree.ElementTree as ET
from typing import Any

import mujoco
import numpy as np
import pinocchio as pin
from franky_sim.mujoco_simulator import FrankaMujocoRobot, MujocoSimulator
from franky_sim.simulation_server import SimulationServer

KV = (450.0, 450.0, 350.0, 350.0, 200.0, 200.0, 60.0)
FINGER_GAIN = 5000.0
WALL = 0.015  # [m] thickness of a hole's walls
INITIAL_Q = (0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.785)


def _box(parent: ET.Element, name: str, pos: tuple, half: tuple, **kw: str) -> ET.Element:
    body = ET.SubElement(parent, "body", name=name, pos=" ".join(map(str, pos)))
    ET.SubElement(body, "geom", type="box", size=" ".join(map(str, half)), friction="0.3 0.005 0.0001", **kw)
    return body


def build(scene: dict[str, Any]) -> SimulationServer:
    sim = MujocoSimulator()
    sim.init()
    robot = sim.add_robot(initial_q=INITIAL_Q, kv=KV)
    top, depth = scene["top_z"], scene["depth"]
    for k, (x, y, side) in enumerate(scene["holes"]):
        h = side / 2 + WALL / 2
        for j, (dx, dy, hx, hy) in enumerate([(h, 0, WALL / 2, side / 2 + WALL), (-h, 0, WALL / 2, side / 2 + WALL),
                                              (0, h, side / 2, WALL / 2), (0, -h, side / 2, WALL / 2)]):
            _box(sim.worldbody, f"wall{k}_{j}", (x + dx, y + dy, top - depth / 2), (hx, hy, depth / 2))
        _box(sim.worldbody, f"floor{k}", (x, y, top - depth - 0.005), (side / 2 + WALL, side / 2 + WALL, 0.005))
    for k, (x, y, side, length, mass) in enumerate(scene["pegs"]):
        body = ET.SubElement(sim.worldbody, "body", name=f"peg{k}", pos=f"{x} {y} {length / 2 + 0.0005}")
        ET.SubElement(body, "freejoint")
        ET.SubElement(body, "geom", type="box", size=f"{side / 2} {side / 2} {length / 2}", mass=str(mass),
                      friction="0.8 0.005 0.0001")
    hand = next(b for b in sim.worldbody.iter("body") if b.get("name") == "robot0_hand")
    ET.SubElement(hand, "site", name="ft_site", pos="0 0 0")
    sensors = ET.SubElement(sim.scene, "sensor")
    ET.SubElement(sensors, "force", site="ft_site", name="ft_force")
    ET.SubElement(sensors, "torque", site="ft_site", name="ft_torque")
    robot.__class__ = SensedRobot
    robot._kp_hand = np.array([FINGER_GAIN, FINGER_GAIN])
    return SimulationServer(sim)


class SensedRobot(FrankaMujocoRobot):
    """The robot whose state carries the pose from q and the flange sensor's wrench."""

    @property
    def state(self) -> Any:
        s = super().state
        model, data = self._model, self._data
        ee = self.kinematics(np.asarray(s.q)).copy()
        hand = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "robot0_hand")
        site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "ft_site")
        rot = data.site_xmat[site].reshape(3, 3)
        origin = data.site_xpos[site]
        g = np.array([0.0, 0.0, -9.81])
        f_s, m_s = rot @ data.sensordata[0:3], rot @ data.sensordata[3:6]
        # the sensor gives the wrench of the arm on the hand's subtree; the environment's
        # wrench on the hand is what remains once its weight and the load's are removed
        mass = model.body_subtreemass[hand]
        com = data.subtree_com[hand]
        load_com = origin + rot @ np.asarray(self.F_x_Cload)
        force = -f_s - mass * g - self.m_load * g
        torque = -m_s - np.cross(com - origin, mass * g) - np.cross(load_com - origin, self.m_load * g)
        torque = torque - np.cross(ee.translation - origin, force)  # about the end effector
        wrench = tuple(np.concatenate([force, torque]).tolist())
        k_wrench = tuple(np.concatenate([ee.rotation.T @ force, ee.rotation.T @ torque]).tolist())
        return s.replace(O_T_EE=self.to_franka_pose(pin.SE3(ee)), O_F_ext_hat_K=wrench, K_F_ext_hat_K=k_wrench)


def main() -> None:
    with open(sys.argv[1]) as f:
        server = build(json.load(f))
    server.init()
    print(f"ready {server.sim.robots[0].hostname}", flush=True)
    server.run_forever(realtime=True)


if __name__ == "__main__":
    main()
