#!/usr/bin/env python3
"""Diagnostic (not run by compare_dmp.sh): how do the kernels' width and
their margin beyond the movement's ends limit a fit? Re-implements primo's
formulation and fit in float64 (rustdoc of primo_core::dmp: linear
phase, normalized Gaussian kernels centred at (k − m)/(K − 1 − 2m), exact
spring with the forcing held at mid-step, least squares on positions, no
ridge) with the kernel overlap h·Δc² and the margin m as parameters.
primo's fits use 0.7 and choose m = 0 or 1 (skills: 2.0, m = 0);
movement_primitives' kernels are wider (0.8 at the next centre,
h·Δc² ≈ 0.22). Demonstrations at 1 kHz, errors at 1 ms; the poses'
positions too (the orientations are fitted alike, as rotation vectors).

Usage: bench/compare_dmp.sh --kernel-width (it needs compare_dmp's venv).
"""
import numpy as np
from scipy.linalg import expm

from compare_dmp import CARTESIAN, CASES

ALPHA, BETA = 25.0, 25.0 / 4


def rmse(fn, tau, k, overlap, margin=0.0, h=1e-4):
    n = round(tau / h)
    t = np.arange(n + 1) * h
    y = fn(t)
    y0, g = y[0], y[-1]
    ranges = y.max(0) - y.min(0)
    amp = np.where(np.abs(g - y0) < 0.1 * ranges, 1.0, g - y0)  # loops keep a = 1
    # The spring, discretized exactly with the forcing held over each step.
    m = np.zeros((3, 3))
    m[:2, :2] = np.array([[0, 1], [-ALPHA * BETA, -ALPHA]]) * h / tau
    m[1, 2] = h / tau
    e = expm(m)
    ad, bd = e[:2, :2], e[:2, 2]
    s = np.minimum((t[:-1] + h / 2) / tau, 1.0)
    span = k - 1 - 2 * margin  # kernel spacings between the ends
    centres = (np.arange(k) - margin) / span
    psi = np.exp(-overlap * span**2 * (s[:, None] - centres) ** 2)
    phi = np.where(s[:, None] < 1, psi / psi.sum(1, keepdims=True), 0.0)
    resp, free = np.zeros((n + 1, k)), np.ones(n + 1)  # kernel responses, unforced
    x, xf = np.zeros((2, k)), np.array([1.0, 0.0])
    for i in range(n):
        x = ad @ x + np.outer(bd, phi[i])
        xf = ad @ xf
        resp[i + 1], free[i + 1] = x[0], xf[0]
    demo, out = slice(0, n + 1, 10), slice(0, n + 1, 10)  # 1 kHz both
    err = []
    for d in range(y.shape[1]):
        base = g[d] + (y0[d] - g[d]) * free
        w = np.linalg.lstsq(amp[d] * resp[demo], y[demo, d] - base[demo], rcond=None)[0]
        err.append(base[out] + amp[d] * resp[out] @ w - y[out, d])
    return float(np.sqrt(np.mean(np.square(err))))


if __name__ == "__main__":
    cases = [(name, fn, tau) for name, fn, tau, _ in CASES]
    cases += [(name[:10] + " pos", lambda t, fn=fn: fn(t)[:, :3], tau) for name, fn, tau in CARTESIAN]
    overlaps = (2.0, 1.0, 0.7, 0.5, 0.25)
    print("RMSE by kernel overlap h·Δc² (no margin):", "  ".join(f"{o:>8}" for o in overlaps))
    for name, fn, tau in cases:
        for k in (30, 10):
            print(f"{name:14} K={k:<2}", "  ".join(f"{rmse(fn, tau, k, o):.2e}" for o in overlaps))
    kernels = (10, 15, 20, 25, 30, 40)
    print("RMSE with one kernel spacing beyond each end / with none, overlap 0.7, by K:",
          "  ".join(f"{k:>5}" for k in kernels))
    for name, fn, tau in cases:
        ratios = [rmse(fn, tau, k, 0.7, 1.0) / rmse(fn, tau, k, 0.7) for k in kernels]
        print(f"{name:14}", "  ".join(f"{r:5.2f}" for r in ratios))
