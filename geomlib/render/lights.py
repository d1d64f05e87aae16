"""Lights of a render: camera-relative three-point lighting, or user lights in world coordinates."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from geomlib.render.options import _as_rgb
from geomlib.render.shading import unit
from geomlib.validate import MeshError, as_array, check_choice, check_float

__all__ = ["light_specs", "add_lights"]

# Camera-relative 3-point lighting: (direction towards the light in camera coordinates, intensity).
# Camera coordinates: +x right, +y up, +z from the scene towards the viewer.
_KEY = ((-0.65, 0.55, 0.55), 2.8)
_FILL = ((0.85, 0.05, 0.50), 0.9)
_RIM = ((0.20, 0.60, -1.0), 1.4)


def _frame_to_z(z: np.ndarray) -> np.ndarray:
    """A rotation whose third column is the unit vector ``z`` (pose of a light shining along -z)."""
    z = z / np.linalg.norm(z)
    helper = np.array([0.0, 1.0, 0.0]) if abs(z[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    R = np.eye(4)
    R[:3, 0], R[:3, 1], R[:3, 2] = x, np.cross(z, x), z
    return R


def light_specs(light, where: str) -> list[dict]:
    """Validate a list of user light specs (world coordinates)."""
    if isinstance(light, dict):
        light = [light]
    if not isinstance(light, Sequence) or isinstance(light, str) or len(light) == 0:
        raise MeshError(
            f"{where}: light must be 'directional', 'spot' or a non-empty list of light dicts, got {light!r}"
        )
    out = []
    for i, s in enumerate(light):
        if not isinstance(s, dict):
            raise MeshError(f"{where}: light[{i}] must be a dict with a 'type', got {s!r}")
        kind = check_choice(s.get("type"), f"light[{i}]['type']", ("directional", "spot", "point"), where=where)
        known = {"type", "direction", "position", "target", "color", "intensity", "inner_cone_deg", "outer_cone_deg"}
        extra = sorted(set(s) - known)
        if extra:
            raise MeshError(f"{where}: light[{i}] has unknown keys {extra}; known keys are {sorted(known)}")
        spec = {
            "type": kind,
            "color": _as_rgb(s.get("color", (1.0, 1.0, 1.0)), f"light[{i}]['color']", where),
            "intensity": check_float(s.get("intensity", 3.0), f"light[{i}]['intensity']", minimum=0.0, where=where),
        }
        if kind == "directional":
            if "direction" not in s:
                raise MeshError(
                    f"{where}: light[{i}] is directional and needs a 'direction' (the way the light travels)"
                )
            d = as_array(s["direction"], f"light[{i}]['direction']", shape=(3,), where=where)
            if np.linalg.norm(d) == 0:
                raise MeshError(f"{where}: light[{i}]['direction'] is the zero vector")
            spec["direction"] = d / np.linalg.norm(d)
        else:
            if "position" not in s:
                raise MeshError(f"{where}: light[{i}] is a {kind} light and needs a 'position'")
            spec["position"] = as_array(s["position"], f"light[{i}]['position']", shape=(3,), where=where)
            if "target" in s:
                spec["target"] = as_array(s["target"], f"light[{i}]['target']", shape=(3,), where=where)
            outer = check_float(
                s.get("outer_cone_deg", 30.0), f"light[{i}]['outer_cone_deg']", minimum=0.1, maximum=89.9, where=where
            )
            inner = check_float(
                s.get("inner_cone_deg", 0.6 * outer),
                f"light[{i}]['inner_cone_deg']",
                minimum=0.0,
                maximum=outer,
                where=where,
            )
            spec["outer"], spec["inner"] = np.radians(outer), np.radians(inner)
        out.append(spec)
    return out


def add_lights(scene, pyrender, light, specs, pose, *, center, c0, s0, shadows: bool, where: str):
    """Add the lights to a pyrender scene; return the shadow render flags they need.

    Parameters
    ----------
    light : str
        ``"directional"`` or ``"spot"`` (camera-relative key light), used when ``specs`` is None.
    specs : list of dict or None
        User lights from :func:`light_specs`, in world coordinates.
    pose : (4, 4)
        Camera-to-world pose in the normalised frame (mesh centred, diagonal 1).
    center, c0, s0
        Mesh centre in the normalised frame, and the normalisation ``x -> (x - c0) / s0``.
    """
    R = pose[:3, :3]
    cam_pos = pose[:3, 3]
    flags = pyrender.RenderFlags.NONE
    if specs is None:
        for k, (dcam, inten) in enumerate((_KEY, _FILL, _RIM)):
            towards = R @ unit(np.asarray(dcam, dtype=np.float64))
            if k == 0 and light == "directional":
                scene.add(pyrender.DirectionalLight(intensity=inten), pose=_frame_to_z(towards))
                if shadows:
                    flags |= pyrender.RenderFlags.SHADOWS_DIRECTIONAL
                continue
            # Fill and rim are far point lights (directional in effect) so only the key casts shadows:
            # pyrender's shadow flags apply to every light of a type, and each shadow costs a lot on llvmpipe.
            dist = 30.0 if k > 0 else 1.5 * float(np.linalg.norm(cam_pos - center)) + 1.0
            node_pose = _frame_to_z(towards)
            node_pose[:3, 3] = center + towards * dist
            if k > 0:
                scene.add(pyrender.PointLight(intensity=inten * dist**2), pose=node_pose)
                continue
            outer = float(min(np.arctan2(0.5, dist) * 1.6, np.radians(80.0)))
            scene.add(
                pyrender.SpotLight(intensity=inten * dist**2, innerConeAngle=0.6 * outer, outerConeAngle=outer),
                pose=node_pose,
            )
            if shadows:
                flags |= pyrender.RenderFlags.SHADOWS_SPOT
        return flags
    for s in specs:
        if s["type"] == "directional":
            scene.add(
                pyrender.DirectionalLight(color=s["color"], intensity=s["intensity"]),
                pose=_frame_to_z(-s["direction"]),
            )
            if shadows:
                flags |= pyrender.RenderFlags.SHADOWS_DIRECTIONAL
            continue
        pos = (s["position"] - c0) / s0
        aim = ((s["target"] - c0) / s0 if "target" in s else center) - pos
        if np.linalg.norm(aim) == 0:
            raise MeshError(f"{where}: a {s['type']} light sits exactly at its target")
        node_pose = _frame_to_z(-aim)
        node_pose[:3, 3] = pos
        # Irradiance falls off with squared distance, which the normalised frame divided by s0.
        inten = s["intensity"] / s0**2
        if s["type"] == "spot":
            lt = pyrender.SpotLight(
                color=s["color"], intensity=inten, innerConeAngle=s["inner"], outerConeAngle=s["outer"]
            )
            if shadows:
                flags |= pyrender.RenderFlags.SHADOWS_SPOT
        else:
            lt = pyrender.PointLight(color=s["color"], intensity=inten)
        scene.add(lt, pose=node_pose)
    return flags
