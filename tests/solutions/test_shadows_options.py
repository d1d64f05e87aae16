"""The shadow options travel as one checked ``ShadowOptions`` (issue 25, item 4).

Each public function validates the options once, at its entry; the functions it calls receive the
checked object. A validation is counted where one of the four functions that thread the options
checks the PCF size (``check_int`` asked about ``pcf``), in whichever module does it; the student
tasks below them (``pcf_visibility``) check their own arguments, as their contract says.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import solutions.shadows.lookup as lookup
from geomlib.validate import MeshError
from solutions.shadows import (
    CLASSIC_CAMERA,
    CLASSIC_LIGHT,
    eye_gbuffer,
    light_visibility,
    render_with_shadows,
    shadow_visibility,
)
from solutions.shadows.scene import classic_scene

THREADING = {"render_with_shadows", "light_visibility", "point_shadow_visibility", "shadow_visibility"}
POINT = {"type": "point", "position": np.array([0.2, -0.3, 2.6])}


@pytest.fixture(scope="module")
def scene():
    return classic_scene()


@pytest.fixture(scope="module")
def eye(scene):
    return eye_gbuffer(scene, CLASSIC_CAMERA, (64, 48))


@pytest.fixture
def pcf_checks(monkeypatch):
    """Count the checks of ``pcf`` in the modules that check it (lookup before the change, options after)."""
    import importlib

    calls = []
    modules = [lookup]
    try:  # the options module exists since the options were bundled
        modules.append(importlib.import_module("solutions.shadows.options"))
    except ImportError:
        pass
    for module in modules:
        real = module.check_int

        def counting(value, name, *args, _real=real, **kwargs):
            if name == "pcf" and kwargs.get("where") in THREADING:
                calls.append(kwargs.get("where"))
            return _real(value, name, *args, **kwargs)

        monkeypatch.setattr(module, "check_int", counting)
    return calls


@pytest.mark.parametrize("light", ["directional", "point"])
def test_options_validated_once_per_call(scene, eye, pcf_checks, light):
    L = CLASSIC_LIGHT if light == "directional" else POINT
    light_visibility(scene, eye, L, map_size=64, pcf=3)
    assert pcf_checks == ["light_visibility"], f"pcf was checked in {pcf_checks}"


def test_keywords_and_options_give_the_same_result(scene, eye):
    from solutions.shadows import ShadowOptions

    kw = dict(pcf=5, slope_bias=2.0, pcf_sampling="poisson", pcf_samples=8)
    a, Da = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=128, **kw)
    b, Db = light_visibility(scene, eye, CLASSIC_LIGHT, map_size=128, options=ShadowOptions(**kw))
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(Da, Db)
    img_kw = render_with_shadows(scene, CLASSIC_CAMERA, POINT, size=(48, 32), map_size=64, pcf=3, cull="back")
    img_opt = render_with_shadows(
        scene, CLASSIC_CAMERA, POINT, size=(48, 32), map_size=64, options=ShadowOptions(pcf=3, cull="back")
    )
    np.testing.assert_array_equal(img_kw, img_opt)


def test_shadow_options_are_frozen_and_checked_when_made():
    from solutions.shadows import ShadowOptions

    opts = ShadowOptions(pcf=3, bounds=[[0, 0, 0], [1, 1, 1]])
    assert opts.bounds.dtype == np.float64 and opts.bounds.shape == (2, 3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        opts.pcf = 5
    assert dataclasses.replace(opts, pcf=5).pcf == 5
    for bad, message in (
        (dict(pcf=4), "ShadowOptions: pcf must be odd"),
        (dict(cull="sideways"), "ShadowOptions: cull must be one of 'front', 'back', 'none'; got 'sideways'"),
        (dict(pcf_sampling="random"), "ShadowOptions: pcf_sampling must be one of 'grid', 'poisson'; got 'random'"),
        (dict(frustum_fix=1), "ShadowOptions: frustum_fix must be True or False"),
        (dict(bias=-1.0), "bias"),
        (dict(bounds=[0, 1]), "bounds"),
    ):
        with pytest.raises(MeshError, match=message):
            ShadowOptions(**bad)


def test_bad_keyword_named_by_the_public_function(scene, eye):
    with pytest.raises(MeshError, match="light_visibility: cull must be one of"):
        light_visibility(scene, eye, CLASSIC_LIGHT, map_size=32, cull="sideways")
    with pytest.raises(MeshError, match="render_with_shadows: pcf must be odd"):
        render_with_shadows(scene, CLASSIC_CAMERA, CLASSIC_LIGHT, size=(16, 16), map_size=32, pcf=2)
    with pytest.raises(MeshError, match="shadow_visibility: pcf_sampling must be one of"):
        shadow_visibility(np.zeros((1, 3)), np.zeros((1, 3)), np.ones((4, 4)), np.eye(4), pcf_sampling="x")


def test_options_and_keywords_together_refused(scene, eye):
    from solutions.shadows import ShadowOptions

    with pytest.raises(MeshError, match="either as options=ShadowOptions.* or as keywords.*pcf"):
        light_visibility(scene, eye, CLASSIC_LIGHT, map_size=32, pcf=3, options=ShadowOptions())
    with pytest.raises(MeshError, match="options must be a ShadowOptions"):
        light_visibility(scene, eye, CLASSIC_LIGHT, map_size=32, options={"pcf": 3})
