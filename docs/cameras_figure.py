"""Draw docs/cameras.png, the diagram of docs/cameras.md.

Run: ``uv run python docs/cameras_figure.py`` (writes next to this file).

Three panels: eye space seen from the side (the frustum of ``perspective``), the NDC cube, and the
window / image pixel grid (``viewport``, pixel centres, row 0 on top). The numbers in the NDC and
window panels are computed with ``geomlib.camera`` so the figure cannot drift from the code.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from geomlib.camera import perspective, project, viewport  # noqa: E402

NEAR, FAR, FOV = 1.6, 4.5, 50.0
W, H = 6, 4
BLUE, RED, GREY = "#1f5fa8", "#c0392b", "#7f8c8d"


def eye_space(ax):
    t = np.tan(np.radians(FOV) / 2)
    ax.fill([0, -FAR, -FAR, 0], [0, FAR * t, -FAR * t, 0], color=BLUE, alpha=0.08)
    ax.plot([0, -FAR], [0, FAR * t], color=BLUE, lw=1)
    ax.plot([0, -FAR], [0, -FAR * t], color=BLUE, lw=1)
    for z, name in ((NEAR, "near"), (FAR, "far")):
        ax.plot([-z, -z], [-z * t, z * t], color=BLUE, lw=2.5)
        ax.annotate(
            f"{name} plane\nz = -{name}\n"
            + ("$z_{ndc}$ = -1, depth 0" if name == "near" else "$z_{ndc}$ = +1, depth 1"),
            (-z, -z * t),
            xytext=(0, -12),
            textcoords="offset points",
            ha="center",
            va="top",
            fontsize=8.5,
            color=BLUE,
        )
    ax.annotate("", (1.0, 0), (0, 0), arrowprops=dict(arrowstyle="->", lw=1.5))
    ax.annotate("", (0, 1.0), (0, 0), arrowprops=dict(arrowstyle="->", lw=1.5))
    ax.text(1.05, 0, "+z", va="center", fontsize=10)
    ax.text(0, 1.08, "+y (up)", ha="center", fontsize=10)
    ax.annotate("", (-3.2, 0), (-0.05, 0), arrowprops=dict(arrowstyle="->", lw=2, color=RED))
    ax.text(-3.0, -0.12, "camera looks down -z", color=RED, ha="center", va="top", fontsize=9)
    ax.plot([0], [0], "ko", ms=6)
    ax.text(0.1, -0.12, "eye\n(origin)", fontsize=9, va="top")
    arc = np.linspace(-np.radians(FOV) / 2, np.radians(FOV) / 2, 30)
    ax.plot(-0.8 * np.cos(arc), 0.8 * np.sin(arc), color=GREY, lw=1)
    ax.text(-0.9, 0.1, "fov_y", color=GREY, fontsize=9, ha="right")
    ax.text(-2.5, 2.25, "x points into the page (right-handed)", fontsize=8.5, color=GREY, ha="center")
    ax.set_title("1. eye space = look_at(eye, target, up) @ p\n(side view, right-handed)", fontsize=10)
    ax.set_xlim(-4.9, 1.5)
    ax.set_ylim(-3.0, 2.5)


def ndc(ax):
    P = perspective(FOV, W / H, NEAR, FAR)
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]])
    ax.plot(corners[:, 0], corners[:, 1], color=BLUE, lw=2)
    ax.fill(corners[:, 0], corners[:, 1], color=BLUE, alpha=0.08)
    ax.annotate("", (1.45, -1.3), (-1.3, -1.3), arrowprops=dict(arrowstyle="->", lw=1.5))
    ax.annotate("", (-1.3, 1.45), (-1.3, -1.3), arrowprops=dict(arrowstyle="->", lw=1.5))
    ax.text(1.5, -1.3, "$x_{ndc}$", va="center")
    ax.text(-1.3, 1.52, "$y_{ndc}$", ha="center")
    for x, y, lab in ((-1, -1, "(-1, -1)"), (1, 1, "(1, 1)")):
        ax.text(x, y + (0.1 if y > 0 else -0.1), lab, ha="center", va="bottom" if y > 0 else "top", fontsize=9)
    # A counter-clockwise (front-facing) triangle.
    tri = np.array([[-0.5, -0.4], [0.5, -0.4], [0.0, 0.5]])
    ax.fill(tri[:, 0], tri[:, 1], color=RED, alpha=0.25)
    for i in range(3):
        a, b = tri[i], tri[(i + 1) % 3]
        ax.annotate("", b, a, arrowprops=dict(arrowstyle="->", color=RED, lw=1.3))
    ax.text(0, -0.6, "counter-clockwise\n= front face", color=RED, ha="center", va="top", fontsize=8.5)
    z_near = (P @ [0, 0, -NEAR, 1])[2] / (P @ [0, 0, -NEAR, 1])[3]
    z_far = (P @ [0, 0, -FAR, 1])[2] / (P @ [0, 0, -FAR, 1])[3]
    ax.text(
        0,
        -1.75,
        f"cube $[-1, 1]^3$: near plane at $z_{{ndc}}$ = {z_near:+.0f}, far at {z_far:+.0f}\n"
        "$p_{ndc} = p_{clip}[:3] / p_{clip}[3]$,  $p_{clip}$ = P @ V @ p",
        ha="center",
        va="top",
        fontsize=9,
    )
    ax.set_title("2. normalised device coordinates\n(after the perspective divide)", fontsize=10)
    ax.set_xlim(-1.7, 1.8)
    ax.set_ylim(-2.5, 1.8)


def window(ax):
    Vp = viewport(W, H)
    for x in range(W + 1):
        ax.plot([x, x], [0, H], color=GREY, lw=0.8)
    for y in range(H + 1):
        ax.plot([0, W], [y, y], color=GREY, lw=0.8)
    cx, cy = np.meshgrid(np.arange(W) + 0.5, np.arange(H) + 0.5)
    ax.plot(cx.ravel(), cy.ravel(), ".", color=BLUE, ms=5)
    # Pixel [row 0, col 0] is the TOP-left square; its centre is at window (0.5, H - 0.5).
    ax.add_patch(plt.Rectangle((0, H - 1), 1, 1, color=RED, alpha=0.25))
    ax.text(0.5, H - 0.5 + 0.18, "[0, 0]", ha="center", fontsize=8, color=RED)
    r, c = 2, 4
    ax.add_patch(plt.Rectangle((c, H - r - 1), 1, 1, color=RED, alpha=0.12))
    ax.text(c + 0.5, H - r - 0.5 + 0.18, f"[{r}, {c}]", ha="center", fontsize=8, color=RED)
    # Check the labels against the code: the NDC point of that pixel centre projects to (c + .5, r + .5).
    ndc_pt = np.linalg.solve(Vp, [c + 0.5, H - r - 0.5, 0.5, 1.0])[:3]
    xy, _ = project(ndc_pt[None], np.eye(4), W, H)
    assert np.allclose(xy, [[c + 0.5, r + 0.5]])
    ax.annotate(
        f"centre: window ({c + 0.5}, {H - r - 0.5})\nimage xy ({c + 0.5}, {r + 0.5}) = (col + .5, row + .5)",
        (c + 0.5, H - r - 0.5),
        xytext=(c + 0.5, -1.55),
        ha="center",
        fontsize=8.5,
        arrowprops=dict(arrowstyle="->", color=RED, lw=1),
    )
    # Window axes (OpenGL, y up) on the left; image rows (y down) on the right.
    ax.annotate("", (W + 0.02, -0.35), (-0.02, -0.35), arrowprops=dict(arrowstyle="->", lw=1.3))
    ax.text(W / 2, -0.45, "$x_{win}$ = column direction", ha="center", va="top", fontsize=8.5)
    ax.annotate("", (-0.35, H + 0.02), (-0.35, -0.02), arrowprops=dict(arrowstyle="->", lw=1.3))
    ax.text(-0.5, H / 2, "$y_{win}$ (up)", rotation=90, ha="right", va="center", fontsize=8.5)
    ax.annotate("", (W + 0.35, -0.02), (W + 0.35, H + 0.02), arrowprops=dict(arrowstyle="->", lw=1.3, color=BLUE))
    ax.text(W + 0.5, H / 2, "image row (down)", rotation=270, ha="left", va="center", fontsize=8.5, color=BLUE)
    for row in range(H):
        ax.text(W + 0.12, H - row - 0.5, str(row), fontsize=7.5, color=BLUE, va="center")
    ax.text(-0.12, -0.12, "(0, 0)", ha="right", va="top", fontsize=8)
    ax.text(W + 0.12, H + 0.1, f"({W}, {H})", fontsize=8)
    ax.set_title(
        f"3. window = viewport({W}, {H}) @ NDC, and the image array\n"
        f"depth = ($z_{{ndc}}$ + 1) / 2;  image[row, col], row 0 = TOP",
        fontsize=10,
    )
    ax.set_xlim(-1.3, W + 1.4)
    ax.set_ylim(-2.3, H + 0.9)


def main() -> Path:
    fig, axes = plt.subplots(1, 3, figsize=(15, 5.2), gridspec_kw=dict(width_ratios=[1.25, 1, 1.2]))
    for ax, draw in zip(axes, (eye_space, ndc, window), strict=True):
        draw(ax)
        ax.set_aspect("equal")
        ax.axis("off")
    fig.tight_layout()
    out = Path(__file__).with_name("cameras.png")
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


if __name__ == "__main__":
    print(main())
