#!/usr/bin/env python3
"""Cross-check our QSS flying-lap figures against TUM's trajectory_planning_helpers.

Usage
-----
    /usr/bin/python3 tools/qss_crosscheck.py --tph /path/to/trajectory_planning_helpers \
                                   --run-dir runs/limit_fsg_2023_trackdrive

``--tph`` is either the TUM repository root (github.com/TUMFTM/trajectory_planning_helpers)
or its inner ``trajectory_planning_helpers`` package directory.  TUM's code is NOT
vendored here: it is imported from that path at run time.  Only numpy is needed
(the package ``__init__`` pulls scipy/quadprog/matplotlib, so it is bypassed and
only ``calc_vel_profile``, ``conv_filt``, ``calc_t_profile``, ``calc_ax_profile``
are loaded).

Inputs read from ``--run-dir``:
  limit_lines.csv    columns line,s,x,y,heading,curvature,speed; closed lines sampled
                     at equal arc-length steps, lap closes last -> first sample.
  limit_report.json  "envelope": {speed, lateral, accel, brake} g-g-v nodes
                     (ay(v), net a_acc(v), net a_brk(v); linear interpolation, end
                     values held), and per line {"lap_time", ...}.

Our model (the thing being checked):
  corner speed   v with v^2|k| = ay(v)
  forward pass   a = a_acc(v) * sqrt(1 - (v^2|k| / ay(v))^2)
  backward pass  d = a_brk(v) * sqrt(1 - (v^2|k| / ay(v))^2)
  no separate drag term (already inside a_acc / a_brk), v <= top_speed,
  closed lap, lap time = sum 2 ds / (v_i + v_{i+1}) incl. closing step.

TUM's calc_vel_profile (v0.80) model, for comparison:
  corner speed   fixed-point iteration v = sqrt(ay(v) r), stopped when the
                 relative change is < 0.5 % (starting from min(ay)).
  forward        a = min(ax_tyre(v) * (1 - (ay_used/ay_max)^e)^(1/e), ax_machines(v)) - c v^2/m
  backward       d = ax_tyre(v) * (1 - (ay_used/ay_max)^e)^(1/e) + c v^2/m
                 (ax_tyre = ONE column of the ggv, used for both directions)
  integration    explicit: v_{i+1}^2 = v_i^2 + 2 a(v_i, k_i) ds  (backward pass
                 additionally re-evaluates a at the far end once and keeps the smaller)
  closed lap     forward and backward passes over two concatenated laps.

Variants computed:
  A "faithful"  ggv = [v, a_brk, ay], ax_max_machines = [v, a_acc], drag_coeff = 0,
                dyn_model_exp = 2, v_max = top_speed.  Differs from ours in the
                forward pass: TUM gives min(a_brk*ellipse, a_acc), ours a_acc*ellipse.
  B "matched"   identical inputs, but TUM's calc_ax_poss is wrapped so that in
                its forward ('accel_forw') mode it sees ggv ax column = a_acc
                (so min(a_acc*ellipse, a_acc) = a_acc*ellipse, exactly our model),
                while backward keeps a_brk.  TUM's own solver/closing logic is
                untouched; this is the closest possible TUM-side reproduction of
                our model (the public API has only one ax column).
  Both are also run with the lap start rotated by half a lap, to check that
  the closed-lap handling does not depend on where the start/finish line is.

Note on TUM v0.80 closed laps: its backward (braking) pass over the doubled lap
keeps the half that was processed FIRST, so braking for a corner just after the
start/finish line is not propagated back to the end of the lap.  If the lap
start lies inside a braking zone, TUM's profile is infeasible there (too fast at
the last samples) and its lap time is too short.  The rotated run exposes this;
trust the unrotated TUM figure only if the sample at s = 0 is not in a braking
zone (in which case rotated and unrotated agree, or the unrotated one is the
slower/valid one).
"""

import argparse
import csv
import json
import os
import sys
import types

import numpy as np


# ----------------------------------------------------------------------------------------------
# Loading TUM's modules without executing the package __init__ (which needs scipy, quadprog, ...)
# ----------------------------------------------------------------------------------------------
def load_tph(path):
    """Return (calc_vel_profile module, calc_t_profile module, version string or None)."""
    path = os.path.abspath(path)
    pkg_dir = path
    if not os.path.isfile(os.path.join(pkg_dir, "calc_vel_profile.py")):
        pkg_dir = os.path.join(path, "trajectory_planning_helpers")
    if not os.path.isfile(os.path.join(pkg_dir, "calc_vel_profile.py")):
        sys.exit("calc_vel_profile.py not found under %s" % path)

    # Register an empty namespace-like package so that "import trajectory_planning_helpers.X"
    # loads only X (and what X itself imports) from pkg_dir.
    pkg = types.ModuleType("trajectory_planning_helpers")
    pkg.__path__ = [pkg_dir]
    sys.modules["trajectory_planning_helpers"] = pkg
    import trajectory_planning_helpers.calc_vel_profile as cvp
    import trajectory_planning_helpers.calc_t_profile as ctp

    # version from setup.py next to the package, if present
    version = None
    setup_py = os.path.join(os.path.dirname(pkg_dir), "setup.py")
    if os.path.isfile(setup_py):
        for line in open(setup_py):
            line = line.strip()
            if line.startswith("version="):
                version = line.split("=", 1)[1].strip(" ,'\"")
    return cvp, ctp, version


# ----------------------------------------------------------------------------------------------
# Inputs
# ----------------------------------------------------------------------------------------------
def read_lines(csv_path):
    """Return {line_name: dict(s, kappa, v)} as numpy arrays (unclosed)."""
    data = {}
    with open(csv_path) as f:
        for row in csv.DictReader(f):
            d = data.setdefault(row["line"], {"s": [], "kappa": [], "v": []})
            d["s"].append(float(row["s"]))
            d["kappa"].append(float(row["curvature"]))
            d["v"].append(float(row["speed"]))
    return {k: {kk: np.asarray(vv) for kk, vv in d.items()} for k, d in data.items()}


def lap_time_trapz(v, ds):
    """sum 2 ds/(v_i + v_{i+1}) over the closed lap (includes last -> first step)."""
    vc = np.append(v, v[0])
    return float(np.sum(2.0 * ds / (vc[:-1] + vc[1:])))


# ----------------------------------------------------------------------------------------------
# TUM runs
# ----------------------------------------------------------------------------------------------
def run_tum(cvp, kappa, el_lengths, env, top_speed, matched):
    """Call TUM calc_vel_profile(closed=True) with our envelope mapped onto its inputs."""
    v_n = np.asarray(env["speed"], float)
    ay_n = np.asarray(env["lateral"], float)
    acc_n = np.asarray(env["accel"], float)
    brk_n = np.asarray(env["brake"], float)

    ggv = np.column_stack((v_n, brk_n, ay_n))          # tyre ax column = our net braking limit
    ax_max_machines = np.column_stack((v_n, acc_n))    # machine cap = our net accel limit

    original = cvp.calc_ax_poss
    if matched:
        # Forward mode sees ax column = a_acc -> min(a_acc*ellipse, a_acc) = a_acc*ellipse.
        ggv_acc = np.column_stack((v_n, acc_n, ay_n))

        def calc_ax_poss_matched(*args, **kwargs):
            if kwargs.get("mode") == "accel_forw":
                kwargs["ggv"] = ggv_acc
            return original(*args, **kwargs)

        cvp.calc_ax_poss = calc_ax_poss_matched
    try:
        vx = cvp.calc_vel_profile(ax_max_machines=ax_max_machines,
                                  kappa=kappa,
                                  el_lengths=el_lengths,
                                  closed=True,
                                  drag_coeff=0.0,     # drag is already inside a_acc / a_brk
                                  m_veh=1.0,          # irrelevant with drag_coeff = 0
                                  ggv=ggv,
                                  v_max=top_speed,
                                  dyn_model_exp=2.0)  # circular friction ellipse like ours
    finally:
        cvp.calc_ax_poss = original
    return vx


def tum_lap_time(ctp, vx, el_lengths):
    """Lap time with TUM's calc_t_profile (closed: append first speed for the closing step)."""
    t = ctp.calc_t_profile(vx_profile=np.append(vx, vx[0]), el_lengths=el_lengths)
    return float(t[-1])


# ----------------------------------------------------------------------------------------------
def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--tph", required=True, help="TUM repo root or its trajectory_planning_helpers dir")
    ap.add_argument("--run-dir", required=True, help="dir with limit_lines.csv and limit_report.json")
    ap.add_argument("--tol", type=float, default=0.5, help="flag relative lap-time differences above this %%")
    args = ap.parse_args()

    cvp, ctp, version = load_tph(args.tph)
    print("TUM trajectory_planning_helpers: %s (version %s)" % (os.path.abspath(args.tph), version))

    lines = read_lines(os.path.join(args.run_dir, "limit_lines.csv"))
    report = json.load(open(os.path.join(args.run_dir, "limit_report.json")))
    env = report["envelope"]
    top_speed = float(report["top_speed"])
    print("top_speed %.4f m/s, envelope nodes %d" % (top_speed, len(env["speed"])))

    flagged = False
    for name, d in lines.items():
        s, kappa, v_ours = d["s"], d["kappa"], d["v"]
        n = s.size
        ds = s[-1] / (n - 1)                 # all steps equal, closing step included
        el_lengths = np.full(n, ds)          # closed: len(el_lengths) == len(kappa)
        ours = report.get(name, {}).get("lap_time")
        print("\n== %s: n=%d ds=%.6f m length=%.4f m (json %.4f)" %
              (name, n, ds, n * ds, report.get(name, {}).get("length", float("nan"))))
        print("   ours (json lap_time)                : %.4f s" % ours)
        print("   ours (recomputed from csv speeds)   : %.4f s" % lap_time_trapz(v_ours, ds))

        for label, matched in (("A faithful", False), ("B matched ", True)):
            vx = run_tum(cvp, kappa, el_lengths, env, top_speed, matched)
            t_tum = tum_lap_time(ctp, vx, el_lengths)
            t_trap = lap_time_trapz(vx, ds)
            rel = 100.0 * (t_tum - ours) / ours
            dv = vx - v_ours
            i = int(np.argmax(np.abs(dv)))
            # same run with the lap start moved by half a lap (tests closed-lap wrap handling)
            h = n // 2
            vx_rot = np.roll(run_tum(cvp, np.roll(kappa, -h), el_lengths, env, top_speed, matched), h)
            t_rot = lap_time_trapz(vx_rot, ds)
            print("   TUM %s: lap %.4f s (trapz %.4f) diff %+.3f %%  max|dv| %.3f m/s at s=%.1f m "
                  "(TUM %.2f vs ours %.2f, |k|=%.4f)  v[%.2f..%.2f]"
                  % (label, t_tum, t_trap, rel, abs(dv[i]), s[i], vx[i], v_ours[i], abs(kappa[i]),
                     vx.min(), vx.max()))
            dv_rot = np.max(np.abs(vx_rot - vx))
            print("       start rotated by n/2: lap %.4f s, max|dv| vs unrotated %.3f m/s%s"
                  % (t_rot, dv_rot,
                     "  <- TUM start-dependent (see note)" if dv_rot > 0.01 else ""))
            if abs(rel) > args.tol:
                flagged = True
    print("\n%s" % ("some lap-time differences exceed %.2f %%" % args.tol if flagged
                    else "all lap-time differences within %.2f %%" % args.tol))


if __name__ == "__main__":
    main()
