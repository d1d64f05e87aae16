"""Instancing: one stored field placed several times in a world (Task 6).

An instance maps world points into the field's own (volume) frame with an affine transform. With a
translation ``t`` and a **uniform** scale ``s`` (``p_world = s p_local + t``), distances scale by
the same factor: ``phi_world(p) = s phi_local((p - t) / s)``. A non-uniform scale stretches
distances differently per direction, so ``phi_local`` of the mapped point is no longer a distance
(it over- or under-estimates by up to the ratio of the largest to the smallest scale; sphere tracing
then overshoots or crawls); only ``min_k s_k`` times it stays a safe lower bound.
Several instances are combined by ``min`` (their union).
"""

from __future__ import annotations

import numpy as np

from geomlib.validate import MeshError, as_array

from .analytic import as_points
from .scene import as_field

__all__ = ["instances_distance"]


def instances_distance(sdf, P, translations, scales) -> np.ndarray:
    """Distance to the union of ``k`` instances of one field.

    Parameters
    ----------
    sdf : field (see ``scene.as_field``)
        In its local (volume) frame.
    P : (n, 3) array_like
        World points.
    translations : (k, 3) array_like
    scales : (k,) array_like
        Uniform scales, ``> 0``.

    Returns
    -------
    d : (n,) float64
        ``min_k s_k phi((P - t_k) / s_k)``.
    """
    where = "instances_distance"
    phi = as_field(sdf, where)
    P = as_points(P, where)
    T = as_array(translations, "translations", shape=(None, 3), where=where)
    S = as_array(scales, "scales", shape=(len(T),), where=where)
    if len(T) == 0:
        raise MeshError(f"{where}: at least one instance is needed")
    if np.any(S <= 0):
        raise MeshError(f"{where}: scales must be > 0 (uniform scale per instance), got {S}")
    # BEGIN SOLUTION: Task 6 (queries): instancing: d = min over instances of s_k * phi((P - t_k) / s_k)
    d = np.full(len(P), np.inf)
    for t, s in zip(T, S, strict=True):  # a loop over the few instances, each vectorised over points
        d = np.minimum(d, s * np.asarray(phi((P - t) / s), np.float64))
    return d
    # END SOLUTION
