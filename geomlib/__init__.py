"""geomlib.

``geomlib.view(V, F, scalars=...)`` turns a mesh in 3D (see :mod:`geomlib.viewer`).
"""


def __getattr__(name: str):
    # Lazy, so `import geomlib` stays cheap; the viewer module imports NumPy/SciPy only when used.
    if name == "view":
        from geomlib.viewer import view

        return view
    raise AttributeError(f"module 'geomlib' has no attribute {name!r}")
