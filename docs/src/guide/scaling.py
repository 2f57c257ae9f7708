"""Draws scaling.svg, the DMP chapter's figure of the three amplitude
scalings: a reach in x (0 -> 0.6 m) with z rising 0.1 m besides a 0.25 m
via-point bump, fitted with each scaling and run to two new goals: z's goal
onto its start, and the whole movement's amplitude doubled.

Needs the primo package (python/README.md); from the repository's root:

    python docs/src/guide/scaling.py
"""

import pathlib

import numpy as np

import primo

OUT = pathlib.Path(__file__).with_name("scaling.svg")

t = np.linspace(0.0, 1.0, 1001)
s = t * t * (3 - 2 * t)
demo = np.column_stack([0.6 * s, 0.1 + 0.1 * s + 0.25 * np.sin(np.pi * t) ** 2])
start = demo[0]
goals = {
    "z's goal onto its start": [0.6, 0.1],
    "amplitude doubled": list(start + 2 * (demo[-1] - start)),
}
scalings = {"per-dof": "#d62728", "none": "#1f77b4", "global": "#2ca02c"}

# One panel per goal: x across, z up, metres.
W, H, PAD = 330, 300, 40
X0, X1, Z0, Z1 = -0.05, 1.3, 0.0, 0.75


def point(x, z, panel):
    px = PAD + panel * (W + PAD) + (x - X0) / (X1 - X0) * W
    pz = PAD + (Z1 - z) / (Z1 - Z0) * H
    return f"{px:.1f},{pz:.1f}"


def line(xz, panel, colour, dash=""):
    pts = " ".join(point(x, z, panel) for x, z in xz[::10])
    style = f' stroke-dasharray="{dash}"' if dash else ""
    return f'<polyline points="{pts}" fill="none" stroke="{colour}" stroke-width="2"{style}/>'


parts = []
for panel, (title, goal) in enumerate(goals.items()):
    left = PAD + panel * (W + PAD)
    parts.append(f'<rect x="{left}" y="{PAD}" width="{W}" height="{H}" fill="none" stroke="#999"/>')
    parts.append(f'<text x="{left + W / 2}" y="{PAD - 12}" text-anchor="middle">{title}</text>')
    parts.append(f'<text x="{left + W / 2}" y="{PAD + H + 28}" text-anchor="middle">x, m</text>')
    parts.append(f'<text x="{left + 8}" y="{PAD + 16}" font-size="11">z, m</text>')
    for v in (0.0, 0.5, 1.0):
        parts.append(f'<text x="{left + (v - X0) / (X1 - X0) * W}" y="{PAD + H + 14}" '
                     f'text-anchor="middle" font-size="10">{v:g}</text>')
    for v in (0.0, 0.25, 0.5):
        parts.append(f'<text x="{left - 4}" y="{PAD + (Z1 - v) / (Z1 - Z0) * H + 4}" '
                     f'text-anchor="end" font-size="10">{v:g}</text>')
    parts.append(line(demo, panel, "#888", "4 3"))
    for scaling, colour in scalings.items():
        dmp = primo.Dmp.fit(t, demo, names=["x", "z"], scaling=scaling)
        _, run = dmp.run(dt=0.001, goal=goal)
        parts.append(line(run, panel, colour))
    gx, gz = point(*goal, panel).split(",")
    parts.append(f'<circle cx="{gx}" cy="{gz}" r="4" fill="black"/>')

legend = [("demonstration", "#888")] + list(scalings.items())
for i, (name, colour) in enumerate(legend):
    y = PAD + H + 50 + 16 * i
    dash = ' stroke-dasharray="4 3"' if i == 0 else ""
    parts.append(f'<line x1="{PAD}" y1="{y}" x2="{PAD + 30}" y2="{y}" stroke="{colour}" stroke-width="2"{dash}/>')
    parts.append(f'<text x="{PAD + 36}" y="{y + 4}" font-size="12">{name}</text>')
parts.append(f'<text x="{PAD + 200}" y="{PAD + H + 54}" font-size="12">black dot: the new goal; z (up) against x, one run per scaling</text>')

width, height = 2 * (W + PAD) + PAD, PAD + H + 50 + 16 * len(legend) + 10
svg = (f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
       f'font-family="sans-serif" font-size="13">\n<rect width="100%" height="100%" fill="white"/>\n'
       + "\n".join(parts) + "\n</svg>\n")
OUT.write_text(svg)
print(f"wrote {OUT}")
