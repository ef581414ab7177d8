"""``teamsim export ROBOT``: one robot on a floor, as MJCF that plain ``mujoco.MjModel.from_xml_path`` loads."""
from __future__ import annotations

from pathlib import Path

from dm_control import mjcf

from teamsim.config import ConfigError
from teamsim.files import write_atomic
from teamsim.models import ROBOT_BUILDERS, build_robot


def robot_on_floor(kind: str) -> mjcf.RootElement:
    if kind not in ROBOT_BUILDERS:
        raise ConfigError(f"unknown robot {kind!r}; available: {', '.join(ROBOT_BUILDERS)}")
    scene = mjcf.RootElement(model=f"{kind}_on_floor")
    scene.compiler.angle = "radian"  # robot builders write angles in radians
    scene.option.integrator = "implicitfast"
    scene.worldbody.add("light", pos=[0, 0, 4], dir=[0, 0, -1], directional=True)
    scene.worldbody.add("geom", name="floor", type="plane", size=[5, 5, 0.1], rgba=[0.8, 0.8, 0.78, 1])
    frame = scene.attach(build_robot(kind, kind).mjcf)
    frame.add("freejoint")
    frame.pos = [0, 0, 0.002]
    return scene


def export_robot(kind: str, out: Path) -> None:
    if not Path(out).name:  # "", ".", "/": a folder, not a file to write
        raise ConfigError(f"--out {str(out)!r}: expected a file path, e.g. {kind}.xml")
    xml = robot_on_floor(kind).to_xml_string()
    try:
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        write_atomic(Path(out), xml.encode())
    except OSError as exc:
        raise ConfigError(f"--out {out}: not writable ({exc.strerror or exc})") from None
