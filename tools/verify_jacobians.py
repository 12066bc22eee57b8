#!/usr/bin/env python3
"""Independent check of sinsmodel's generated A(t) and H against CasADi automatic differentiation.

The nonlinear strapdown equations (NED navigation frame, FRD body frame, WGS-84, radii frozen at
the true latitude, normal gravity by Somigliana with the WGS-84 free-air term) are written here
from scratch for a true and an error-corrupted navigator. The error state is defined by
C~ = (I - [phi x]) C, dv = v~ - v, dlat, dlon, dh = computed - true, and the instrument error
terms by this file's own table (DESIGN.md §2, §7), not by the project's spec. CasADi
differentiates the error-state derivative at zero error; the result is compared with
`sinsmodel jacobian` at random points for several models, together with the structural sparsity.

Error metric: for a structural non-zero, |generated - casadi| / max(|casadi|, 1e-6 * s_row), with
s_row = max(1, max |casadi row|, |w_b|); a structural zero must have |casadi| <= 1e-14 * s_row.

Exit status: 0 when every model agrees within --tol (relative), 1 otherwise.
"""

import argparse
import json
import math
import subprocess
import sys
import tempfile

import casadi as ca
import numpy as np

# ---------------------------------------------------------------- WGS-84 (independent of the Rust code)
A_WGS = 6378137.0
F_WGS = 1.0 / 298.257223563
E2 = F_WGS * (2.0 - F_WGS)
OMEGA = 7.292115e-5
GM = 3.986004418e14
GAMMA_E = 9.7803253359
GAMMA_P = 9.8321849378
B_WGS = A_WGS * (1.0 - F_WGS)
K_SOM = (B_WGS * GAMMA_P - A_WGS * GAMMA_E) / (A_WGS * GAMMA_E)
M_RATIO = OMEGA**2 * A_WGS**2 * B_WGS / GM


def gravity(lat, h):
    """Normal gravity magnitude (down), Somigliana + WGS-84 free-air series."""
    s2 = ca.sin(lat) ** 2
    g0 = GAMMA_E * (1 + K_SOM * s2) / ca.sqrt(1 - E2 * s2)
    return g0 * (1 - 2 / A_WGS * (1 + F_WGS + M_RATIO - 2 * F_WGS * s2) * h + 3 * h**2 / A_WGS**2)


def radii(lat):
    s2 = ca.sin(lat) ** 2
    rm = A_WGS * (1 - E2) / (1 - E2 * s2) ** 1.5
    rn = A_WGS / ca.sqrt(1 - E2 * s2)
    return rm, rn


def skew(v):
    return ca.vertcat(
        ca.horzcat(0, -v[2], v[1]),
        ca.horzcat(v[2], 0, -v[0]),
        ca.horzcat(-v[1], v[0], 0),
    )


def dcm_from_euler(roll, pitch, yaw):
    cr, sr = ca.cos(roll), ca.sin(roll)
    cp, sp = ca.cos(pitch), ca.sin(pitch)
    cy, sy = ca.cos(yaw), ca.sin(yaw)
    rz = ca.vertcat(ca.horzcat(cy, -sy, 0), ca.horzcat(sy, cy, 0), ca.horzcat(0, 0, 1))
    ry = ca.vertcat(ca.horzcat(cp, 0, sp), ca.horzcat(0, 1, 0), ca.horzcat(-sp, 0, cp))
    rx = ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, cr, -sr), ca.horzcat(0, sr, cr))
    return rz @ ry @ rx


# ---------------------------------------------------------------- instrument terms (DESIGN §2, §7)
def _fx(f, w): return f[0]
def _fy(f, w): return f[1]
def _fz(f, w): return f[2]


TERMS = {}


def term(name, sensor, axis, regressor):
    TERMS[name] = (sensor, "xyz".index(axis), regressor)


for ax in "xyz":
    term(f"eps_{ax}", "gyro", ax, lambda f, w: 1.0)
    term(f"nabla_{ax}", "accel", ax, lambda f, w: 1.0)
# gyro lower-triangular scale/misalignment: kg_ij, gyro i, regressor w_j
for name, i, j in [("kg_11", 0, 0), ("kg_21", 1, 0), ("kg_31", 2, 0), ("kg_22", 1, 1), ("kg_32", 2, 1), ("kg_33", 2, 2)]:
    term(name, "gyro", "xyz"[i], (lambda jj: lambda f, w: w[jj])(j))
# accelerometer full matrix: ka_ij, accel i, regressor f_j
for i in range(3):
    for j in range(3):
        term(f"ka_{i + 1}{j + 1}", "accel", "xyz"[i], (lambda jj: lambda f, w: f[jj])(j))
for i, ax in enumerate("xyz"):
    term(f"d_{ax}", "accel", ax, (lambda ii: lambda f, w: f[ii] ** 2)(i))
LIBRARY = []


def lib(name, sensor, axis, regressor):
    term(name, sensor, axis, regressor)
    LIBRARY.append(name)


for name, i, j, k in [("kaq_x_xy", 0, 0, 1), ("kaq_x_xz", 0, 0, 2), ("kaq_y_xy", 1, 0, 1),
                      ("kaq_y_yz", 1, 1, 2), ("kaq_z_xz", 2, 0, 2), ("kaq_z_yz", 2, 1, 2)]:
    lib(name, "accel", "xyz"[i], (lambda a, b: lambda f, w: f[a] * f[b])(j, k))
for i, ax in enumerate("xyz"):
    lib(f"kas_{ax}", "accel", ax, (lambda ii: lambda f, w: ca.fabs(f[ii]))(i))
for i, ax in enumerate("xyz"):
    lib(f"kao_{ax}", "accel", ax, (lambda ii: lambda f, w: f[ii] * ca.fabs(f[ii]))(i))
for i, gx in enumerate("xyz"):
    for j, fx in enumerate("xyz"):
        lib(f"kgf_{gx}{fx}", "gyro", gx, (lambda jj: lambda f, w: f[jj])(j))
for i, ax in enumerate("xyz"):
    j, k = [a for a in range(3) if a != i]
    lib(f"kgq_{ax}", "gyro", ax, (lambda a, b: lambda f, w: f[a] * f[b])(j, k))
for i, ax in enumerate("xyz"):
    j, k = [a for a in range(3) if a != i]
    lib(f"size_{ax}", "accel", ax, (lambda a, b: lambda f, w: -(w[a] ** 2 + w[b] ** 2))(j, k))

NAV = ["phi_n", "phi_e", "phi_d", "dv_n", "dv_e", "dv_d", "dlat", "dlon", "dh"]
TERM_NAMES = list(TERMS)
ALL_STATES = NAV + TERM_NAMES


# ---------------------------------------------------------------- the nonlinear error dynamics
def build_jacobian_function():
    """CasADi function: point parameters -> (J_A [9 x (9+T)] at zero error, J_H, sparsity)."""
    p = ca.SX.sym("p", 14)  # lat, h, vn ve vd, roll pitch yaw, f_b(3), w_b(3)
    lat, h = p[0], p[1]
    v = p[2:5]
    c = dcm_from_euler(p[5], p[6], p[7])
    f_b, w_b = p[8:11], p[11:14]
    rm0, rn0 = radii(lat)  # frozen at the true latitude

    x = ca.SX.sym("x", len(ALL_STATES))
    phi, dv = x[0:3], x[3:6]
    dlat, dh = x[6], x[8]
    theta = x[9:]

    def w_ie(L):
        return OMEGA * ca.vertcat(ca.cos(L), 0, -ca.sin(L))

    def w_en(L, hh, vv):
        return ca.vertcat(vv[1] / (rn0 + hh), -vv[0] / (rm0 + hh), -vv[1] * ca.tan(L) / (rn0 + hh))

    def derivs(C, vv, L, hh, wb, fb):
        w_in = w_ie(L) + w_en(L, hh, vv)
        c_dot = C @ skew(wb) - skew(w_in) @ C
        g = ca.vertcat(0, 0, gravity(L, hh))
        v_dot = C @ fb - ca.cross(2 * w_ie(L) + w_en(L, hh, vv), vv) + g
        lat_dot = vv[0] / (rm0 + hh)
        lon_dot = vv[1] / ((rn0 + hh) * ca.cos(L))
        h_dot = -vv[2]
        return c_dot, v_dot, lat_dot, lon_dot, h_dot

    # sensor errors from this file's term table
    dw = [0, 0, 0]
    df = [0, 0, 0]
    for k, name in enumerate(TERM_NAMES):
        sensor, axis, reg = TERMS[name]
        contrib = theta[k] * reg(f_b, w_b)
        if sensor == "gyro":
            dw[axis] = dw[axis] + contrib
        else:
            df[axis] = df[axis] + contrib
    w_meas = w_b + ca.vertcat(*dw)
    f_meas = f_b + ca.vertcat(*df)

    c_tilde = (ca.SX.eye(3) - skew(phi)) @ c
    cd_t, vd_t, latd_t, lond_t, hd_t = derivs(c, v, lat, h, w_b, f_b)
    cd_c, vd_c, latd_c, lond_c, hd_c = derivs(c_tilde, v + dv, lat + dlat, h + dh, w_meas, f_meas)

    e_dot = cd_c @ c.T + c_tilde @ cd_t.T
    phi_dot = 0.5 * ca.vertcat(e_dot[1, 2] - e_dot[2, 1], e_dot[2, 0] - e_dot[0, 2], e_dot[0, 1] - e_dot[1, 0])
    err_dot = ca.vertcat(phi_dot, vd_c - vd_t, latd_c - latd_t, lond_c - lond_t, hd_c - hd_t)

    jac = ca.jacobian(err_dot, x)
    # measurements: north/east position error in metres, velocity error, height error
    dlon = x[7]
    z = ca.vertcat(dv[0], dv[1], (rm0 + h) * dlat, (rn0 + h) * ca.cos(lat) * dlon, dh)
    jac_h = ca.jacobian(z, x)
    x0 = ca.DM.zeros(len(ALL_STATES))
    fun = ca.Function("sins_error_jacobian", [p, x], [jac, jac_h])
    return fun, x0, jac.sparsity()


# ---------------------------------------------------------------- the paper's misprints, for self-tests
def corrupt(kind, out, pt):
    """Applies misprint `kind` (DESIGN §4 table) to a sinsmodel JSON result in place."""
    st = out["states"]
    a = out["a"]
    lat = math.radians(pt["lat_deg"])
    rm0, rn0 = (float(r) for r in radii(lat))
    rn = rn0 + pt["h_m"]
    ve = pt["v_ned"][1]
    s, c = math.sin(lat), math.cos(lat)
    idx = {n: i for i, n in enumerate(st)}
    cm = np.array(dcm_from_euler(*[math.radians(v) for v in pt["euler_deg"]]))
    f, w = pt["f_b"], pt["w_b"]
    if kind == 1:
        a[idx["phi_d"]][idx["dlat"]] = -OMEGA * c - ve / (rn * math.cos(2 * lat))
    elif kind == 2:
        a[idx["dv_n"]][idx["dlat"]] = -ve * (2 * OMEGA * c + ve * math.tan(lat) / (rn * c * c))
    elif kind == 3 and "kg_32" in idx:
        a[idx["phi_d"]][idx["kg_32"]] = -cm[0, 1] * w[1]
    elif kind == 4:
        del a[-22:]
    elif kind == 5:
        for i, ax in enumerate("xyz"):
            if f"d_{ax}" in idx:
                for k, row in enumerate(["dv_n", "dv_e", "dv_d"]):
                    if row in idx:
                        a[idx[row]][idx[f"d_{ax}"]] = cm[k, i] * f[i]
    elif kind == 6 and "dh" in idx:
        a[idx["dh"]][idx["dv_d"]] = 0.0


def random_points(n, rng):
    pts = []
    for _ in range(n):
        def rand_vec(max_norm):
            d = rng.normal(size=3)
            return list(d / np.linalg.norm(d) * rng.uniform(0, max_norm))

        pts.append({
            "lat_deg": float(rng.uniform(-80, 80)),
            "h_m": float(rng.uniform(-500, 10000)),
            "v_ned": [float(x) for x in rand_vec(300.0)],
            "euler_deg": [float(rng.uniform(-180, 180)), float(rng.uniform(-89, 89)), float(rng.uniform(-180, 180))],
            "f_b": [float(x) for x in rand_vec(20 * 9.80665)],
            "w_b": [float(x) for x in rand_vec(3.0)],
        })
    return pts


def point_vector(pt):
    return [math.radians(pt["lat_deg"]), pt["h_m"], *pt["v_ned"],
            *[math.radians(v) for v in pt["euler_deg"]], *pt["f_b"], *pt["w_b"]]


def run_sinsmodel(binary, model, points, runtime):
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as fh:
        json.dump(points, fh)
        path = fh.name
    cmd = [binary, "jacobian", "--model", model, "--at", path] + (["--runtime"] if runtime else [])
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise SystemExit(f"sinsmodel failed for {model}: {res.stderr.strip()}")
    return json.loads(res.stdout)


def check_model(binary, model, points, fun, x0, sparsity, tol, corrupt_kind, runtime):
    outs = run_sinsmodel(binary, model, points, runtime)
    worst_abs, worst_rel, worst_at = 0.0, 0.0, None
    problems = []
    states = outs[0]["states"]
    unknown = [s for s in states if s not in ALL_STATES]
    if unknown:
        return [f"states unknown to the independent model: {unknown}"], 0, 0, None, 0
    cols = [ALL_STATES.index(s) for s in states]
    nav_rows = [NAV.index(s) for s in states if s in NAV]
    n = len(states)
    # structural: CasADi's pattern restricted to the model, vs the generated pattern
    cas_struct = set()
    for (i, j) in zip(*sparsity.get_triplet()):
        if NAV[i] in states and ALL_STATES[j] in states:
            cas_struct.add((states.index(NAV[i]), states.index(ALL_STATES[j])))
    gen_struct = {tuple(e) for e in outs[0]["pattern"]}
    missing = gen_struct - cas_struct
    if missing:
        problems.append(f"generated non-zeros that CasADi says are structurally zero: "
                        f"{sorted((states[i], states[j]) for i, j in missing)[:8]}")
    extra_nonzero = set()
    for pt, out in zip(points, outs):
        if corrupt_kind:
            corrupt(corrupt_kind, out, pt)
        ja, jh = fun(point_vector(pt), x0)
        ja = np.array(ja)
        jh = np.array(jh)
        ref = np.zeros((n, n))
        for r_model, s in enumerate(states):
            if s in NAV:
                ref[r_model, :] = ja[NAV.index(s), cols]
        gen = np.array(out["a"], dtype=float)
        if gen.shape != ref.shape:
            problems.append(f"A has shape {gen.shape}, expected {ref.shape}")
            break
        w_norm = float(np.linalg.norm(pt["w_b"]))
        for i in range(n):
            row_scale = max(1.0, float(np.max(np.abs(ref[i]))), w_norm)
            zero_tol = 1e-14 * row_scale
            for j in range(n):
                d = abs(gen[i, j] - ref[i, j])
                worst_abs = max(worst_abs, d)
                if (i, j) in gen_struct:
                    # structural non-zero: relative error, with entries below 1e-6 of the row
                    # scale judged against that (CasADi's attitude rows carry a rounding residue
                    # of ~1e-16*|w| from the body-rate terms that cancel analytically)
                    rel = d / max(abs(ref[i, j]), 1e-6 * row_scale)
                    if rel > worst_rel:
                        worst_rel, worst_at = rel, (states[i], states[j], gen[i, j], ref[i, j])
                elif abs(ref[i, j]) > zero_tol or gen[i, j] != 0.0:
                    extra_nonzero.add((states[i], states[j]))
        # H: rows of z = [dv_n, dv_e, dp_n, dp_e, dp_u]
        h_rows = {"vel_ne": [0, 1], "pos_ne": [2, 3], "pos_h": [4]}
        for name, rows in h_rows.items():
            needs = {"vel_ne": ["dv_n", "dv_e"], "pos_ne": ["dlat", "dlon"], "pos_h": ["dh"]}[name]
            if all(s in states for s in needs):
                if name not in out["h"]:
                    problems.append(f"H {name} missing")
                    continue
                hg = np.array(out["h"][name])
                hr = jh[rows][:, cols]
                d = np.abs(hg - hr)
                rel = float(np.max(d / np.maximum(np.abs(hr), 1e-12)))
                worst_rel = max(worst_rel, rel if np.max(d) > 0 else 0.0)
                worst_abs = max(worst_abs, float(np.max(d)))
    if extra_nonzero:
        problems.append(f"CasADi non-zeros outside the generated pattern: {sorted(extra_nonzero)[:8]}")
    if worst_rel > tol:
        problems.append(f"worst relative error {worst_rel:.3e} > {tol:.1e} at {worst_at}")
    cancelled = len(cas_struct - gen_struct)
    return problems, worst_abs, worst_rel, worst_at, cancelled


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", required=True, help="path of the sinsmodel binary")
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--seed", type=int, default=20131)
    ap.add_argument("--tol", type=float, default=1e-9, help="relative tolerance")
    ap.add_argument("--models", nargs="*", default=None)
    ap.add_argument("--corrupt", type=int, default=0, help="apply paper misprint K (1-6) to the generated A: the check must fail")
    args = ap.parse_args()

    lib_terms = "+".join(LIBRARY)
    models = args.models or ["P13", "P24", "P28", "P31", "P31+vertical", f"P31+{lib_terms}", f"P31+vertical+{lib_terms}"]
    fun, x0, sparsity = build_jacobian_function()
    rng = np.random.default_rng(args.seed)
    points = random_points(args.points, rng)
    failed = False
    overall_abs, overall_rel = 0.0, 0.0
    for model in models:
        label = model if len(model) < 40 else model[:model.index("+", 4)] + "+<27 library terms>"
        for runtime in (False, True):
            problems, wa, wr, at, cancelled = check_model(args.bin, model, points, fun, x0, sparsity, args.tol,
                                                          args.corrupt, runtime)
            path = "runtime" if runtime else "preset "
            status = "FAIL" if problems else "ok"
            print(f"{status:4} {label:32} {path} worst abs {wa:.3e} worst rel {wr:.3e}"
                  f"  (CasADi structural entries that cancel numerically: {cancelled})")
            for p in problems:
                print(f"     - {p}")
            failed |= bool(problems)
            overall_abs, overall_rel = max(overall_abs, wa), max(overall_rel, wr)
    print(f"points {len(points)}, models {len(models)}: worst absolute error {overall_abs:.3e}, "
          f"worst relative error {overall_rel:.3e} (tolerance {args.tol:.1e} relative)")
    print("FAILED" if failed else "PASSED")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
