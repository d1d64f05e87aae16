"""The options of a shadow lookup, bundled and validated once (given).

:class:`ShadowOptions` holds the nine settings that :func:`~.shading.render_with_shadows`,
:func:`~.shading.light_visibility`, :func:`~.cubemap.point_shadow_visibility` and
:func:`~.lookup.shadow_visibility` share. A public function builds one from its keywords (or takes
one as ``options=``) and checks it there, once; the functions it calls receive the checked object.
"""

from __future__ import annotations

from dataclasses import InitVar, dataclass

import numpy as np

from geomlib.validate import MeshError, as_array, check_choice, check_float, check_int

#: The constants are exported by the modules that use them (depth, lookup).
__all__ = ["ShadowOptions"]

#: Accepted values of ``cull``.
CULL_MODES = ("front", "back", "none")
#: Default constant bias, in window-depth units times the map size: ``bias = 1 / size``.
DEFAULT_BIAS_TEXELS = 1.0
#: Default slope factor: how many times the tangent plane's depth change within half a texel is added.
DEFAULT_SLOPE_BIAS = 1.5
#: Steepest NDC depth slope ``|dz/dx|`` used for the bias (surfaces seen edge-on by the light).
DEFAULT_MAX_SLOPE = 20.0
#: How :func:`shadow_visibility` places its PCF samples: a k x k block of texels, or a rotated Poisson disk.
PCF_SAMPLINGS = ("grid", "poisson")


@dataclass(frozen=True, eq=False)
class ShadowOptions:
    """How shadows are looked up; checked when made (an invalid value raises :class:`MeshError`).

    Attributes
    ----------
    bias : float or None
        Constant bias in window-depth units, ``>= 0``; None: ``DEFAULT_BIAS_TEXELS / size``.
    slope_bias : float or None
        Slope factor (see :func:`~.lookup.shadow_bias`), ``>= 0``; None: ``DEFAULT_SLOPE_BIAS``.
    pcf : int
        Odd PCF block size in 1..15; 1 gives hard 0/1 shadows.
    cull : {"front", "back", "none"}
        Culling in the depth pass.
    frustum_fix : bool
        Treat points outside the light frustum as lit (Task 6).
    bounds : (2, 3) array or None
        Box a directional light's map is fitted to (None: the scene's bounding box).
    max_slope : float
        Clamp of the NDC depth slope (see :func:`~.lookup.receiver_depth_gradient`), ``>= 0``.
    pcf_sampling : {"grid", "poisson"}
        A ``pcf x pcf`` block of texels, or ``pcf_samples`` samples on a rotated Poisson disk.
    pcf_samples : int
        Disk samples for ``pcf_sampling="poisson"``, 1..256.

    ``where`` (not stored) names the function in error messages.
    """

    bias: float | None = None
    slope_bias: float | None = None
    pcf: int = 1
    cull: str = "none"
    frustum_fix: bool = True
    bounds: np.ndarray | None = None
    max_slope: float = DEFAULT_MAX_SLOPE
    pcf_sampling: str = "grid"
    pcf_samples: int = 16
    where: InitVar[str] = "ShadowOptions"

    def __post_init__(self, where: str) -> None:
        def put(name, value):
            object.__setattr__(self, name, value)

        if self.bias is not None:
            put("bias", check_float(self.bias, "bias", minimum=0.0, where=where))
        if self.slope_bias is not None:
            put("slope_bias", check_float(self.slope_bias, "slope_bias", minimum=0.0, where=where))
        k = check_int(self.pcf, "pcf", minimum=1, maximum=15, where=where)
        if k % 2 == 0:
            raise MeshError(f"{where}: pcf must be odd (a k x k block centred on the texel), got {k}")
        put("pcf", k)
        check_choice(self.cull, "cull", CULL_MODES, where=where)
        if not isinstance(self.frustum_fix, bool | np.bool_):
            raise MeshError(f"{where}: frustum_fix must be True or False, got {self.frustum_fix!r}")
        if self.bounds is not None:
            put("bounds", as_array(self.bounds, "bounds", shape=(2, 3), where=where))
        put("max_slope", check_float(self.max_slope, "max_slope", minimum=0.0, where=where))
        check_choice(self.pcf_sampling, "pcf_sampling", PCF_SAMPLINGS, where=where)
        put("pcf_samples", check_int(self.pcf_samples, "pcf_samples", minimum=1, maximum=256, where=where))

    @classmethod
    def of(cls, options, where: str, keywords: dict, defaults: dict) -> ShadowOptions:
        """The options of a call: ``options`` when given (then every keyword must be at its default), else the keywords.

        Parameters
        ----------
        options : ShadowOptions or None
        where : str
            The public function, for messages.
        keywords : dict
            The shadow options the function received as keywords.
        defaults : dict
            Their defaults in that function's signature.
        """
        if options is None:
            return cls(**keywords, where=where)
        if not isinstance(options, ShadowOptions):
            raise MeshError(f"{where}: options must be a ShadowOptions, got {type(options).__name__}")
        given = [k for k, v in keywords.items() if not _is_default(v, defaults[k])]
        if given:
            raise MeshError(
                f"{where}: give the shadow options either as options=ShadowOptions(...) or as keywords, not both "
                f"(also given: {', '.join(given)})"
            )
        return options


def _is_default(value, default) -> bool:
    if value is default:
        return True
    return isinstance(value, bool | int | float | str) and type(value) is type(default) and value == default


def keyword_defaults(fn, names=None) -> dict:
    """The defaults of ``fn``'s parameters that are fields of :class:`ShadowOptions`."""
    import inspect

    fields = set(ShadowOptions.__dataclass_fields__) - {"where"} if names is None else set(names)
    return {name: p.default for name, p in inspect.signature(fn).parameters.items() if name in fields}
