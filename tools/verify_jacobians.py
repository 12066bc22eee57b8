#!/usr/bin/env python3
"""Independent check of sinsmodel's generated A(t) and H against CasADi automatic differentiation.

The nonlinear strapdown equations (NED navigation frame, FRD body frame, WGS-84, radii frozen at
the true latitude, normal gravity by Somigliana with the WGS-84 free-air term) are written here
from scratch for a true and an error-corrupted navigator, and so are the measurements (velocity,
north/east position in metres, height). The error state is defined by C~ = (I - [phi x]) C,
dv = v~ - v, dlat, dlon, dh = computed - true. The instrument error terms are read from the spec
(`model-spec/terms.toml`: each term's sensor, axis and regressor, the regressor translated into
CasADi; anything the translator does not know is rejected loudly): a term corrupts its sensor,
w_meas = w + theta * r(f, w) or f_meas = f + theta * r(f, w), and CasADi differentiates the
error-state derivative of the nonlinear equations at zero error. Nothing of the spec's A(t), H or
composition rule is read. The result is compared with `sinsmodel jacobian` at random points for
every preset (with and without the vertical channel) and for the largest preset plus every other
spec term, so every spec term is checked by default; the structural sparsity is compared too.

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


# ---------------------------------------------------------------- instrument terms, read from the spec
import ast  # noqa: E402
import os  # noqa: E402
import tomllib  # noqa: E402

SPEC_DIR = os.environ.get("SINSMODEL_SPEC_DIR", os.path.join(os.path.dirname(__file__), "..", "model-spec"))


class SpecTranslationError(Exception):
    """A spec regressor the checker cannot translate into CasADi."""


_METHODS = {
    "abs": lambda x: ca.fabs(x),
    "sqrt": lambda x: ca.sqrt(x),
    "sin": lambda x: ca.sin(x),
    "cos": lambda x: ca.cos(x),
    "tan": lambda x: ca.tan(x),
}


def translate_regressor(text, term):
    """Turns a spec regressor (Rust syntax: `f.x * f.y`, `f.z.powi(2)`, `-(w.y.powi(2) + w.z.powi(2))`,
    `w.x * w.y - dw.z`) into a function (f, w, dw, df) -> CasADi expression. Only literals, f.x..df.z,
    + - * /, unary minus and the methods abs sqrt sin cos tan powi(integer) are accepted; anything
    else raises."""
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as e:
        raise SpecTranslationError(f"term `{term}`: regressor `{text}`: not an expression the checker reads ({e.msg})")

    def fail(node, why):
        raise SpecTranslationError(f"term `{term}`: regressor `{text}`: cannot translate `{ast.unparse(node)}` ({why})")

    signals = ("f", "w", "dw", "df")

    def tr(node):
        if isinstance(node, ast.Constant) and type(node.value) in (int, float):
            v = float(node.value)
            return lambda s: v
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
            if node.value.id in signals and node.attr in ("x", "y", "z"):
                i, k = signals.index(node.value.id), "xyz".index(node.attr)
                return lambda s: s[i][k]
            fail(node, "signals are f.x f.y f.z, w.x w.y w.z, dw.x dw.y dw.z and df.x df.y df.z")
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            inner = tr(node.operand)
            return (lambda s: -inner(s)) if isinstance(node.op, ast.USub) else inner
        if isinstance(node, ast.BinOp):
            a, b = tr(node.left), tr(node.right)
            ops = {ast.Add: lambda x, y: x + y, ast.Sub: lambda x, y: x - y,
                   ast.Mult: lambda x, y: x * y, ast.Div: lambda x, y: x / y}
            op = ops.get(type(node.op))
            if op is None:
                fail(node, "operators are + - * /")
            return lambda s: op(a(s), b(s))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and not node.keywords:
            recv, name = tr(node.func.value), node.func.attr
            if name == "powi":
                if len(node.args) != 1 or not (isinstance(node.args[0], ast.Constant) and type(node.args[0].value) is int):
                    fail(node, "powi takes one integer literal")
                k = node.args[0].value
                return lambda s: recv(s) ** k
            if name in _METHODS and not node.args:
                m = _METHODS[name]
                return lambda s: m(recv(s))
            fail(node, f"methods are {' '.join(sorted(_METHODS))} powi")
        fail(node, "not arithmetic over f, w, dw and df")

    body = tr(tree.body)
    return lambda f, w, dw=(0, 0, 0), df=(0, 0, 0): body((f, w, dw, df))


# Accelerometer inner lever arms, written independently of the spec: accelerometer i sits at
# r = theta along body axis j, so it reads the specific force of that point,
# f + w x (w x r) + dw x r, along its axis i (w the inertial body rate, dw its derivative).
# name -> (accelerometer axis i, coordinate j)
INNER_LEVER = {f"size_{i}" + ("" if i == j else f"_{j}"): ("xyz".index(i), "xyz".index(j))
               for i in "xyz" for j in "xyz"}

# Accelerometer delays behind the gyros, written independently of the spec: accelerometer i
# reads at stamp t the specific force of t - theta, the signal about the point being
# f(s) = f_b + s df_b (df_b its body-frame rate of change). name -> accelerometer axis i
ACCEL_DELAY = {f"tau_{i}": "xyz".index(i) for i in "xyz"}

# the accelerometer terms derived from this file's physics: name -> (axis, kind, what it is)
ACCEL_PHYSICS = {
    **{n: (i, ("inner_lever", j), "an inner lever arm") for n, (i, j) in INNER_LEVER.items()},
    **{n: (i, ("delay",), "the delay") for n, i in ACCEL_DELAY.items()},
}


# GNSS measurement terms, written independently of the spec: what each one does to the fix.
# ("time_offset",): the fix stamped t is the trajectory at t + theta [s];
# ("lever", k): the antenna sits at IMU position + C l, l = theta along body axis k [m]; its
# velocity adds C (w_b x l) (w_b the body rate; the navigation-frame rate is left out).
GNSS_PHYSICS = {
    "dt_gnss": ("time_offset",),
    "lever_x": ("lever", 0),
    "lever_y": ("lever", 1),
    "lever_z": ("lever", 2),
}


# Velocity-reference terms, written independently of the spec: the reference (odometer, DVL)
# measures the velocity in its own frame r, whose attitude against the IMU body frame is the
# rotation of roll, pitch, yaw (mount_x, mount_y, mount_z): C_r^b = dcm_from_euler(mount), and
# it reads v^r = (C_r^b)^T v^b; ("time_offset",): the row stamped t is v^b at t + theta [s]
# (the body velocity's rate from the true navigation equations); ("scale",): its forward reading
# is (1 + theta) times the true one.
REFERENCE_PHYSICS = {"mount_x": ("mount", 0), "mount_y": ("mount", 1), "mount_z": ("mount", 2),
                     "dt_ref": ("time_offset",), "k_ref": ("scale",)}


# Attitude-reference terms, written independently of the spec: the reference (a second INS, an
# AHRS) gives the attitude of its own frame r, turned against the IMU body frame by roll, pitch,
# yaw (att_mount_x, att_mount_y, att_mount_z): C_r^b = dcm_from_euler(mount), C_r^n = C_b^n C_r^b;
# ("time_offset",): the row stamped t is that attitude at t + theta [s] (C's rate from the true
# navigation equations).
ATTITUDE_PHYSICS = {"att_mount_x": ("mount", 0), "att_mount_y": ("mount", 1),
                    "att_mount_z": ("mount", 2), "dt_att": ("time_offset",)}


# The tables of the terms that enter the measurements, by the spec's `sensor`.
MEASUREMENT_PHYSICS = {"gnss": (GNSS_PHYSICS, "GNSS_PHYSICS", "GNSS"),
                       "reference": (REFERENCE_PHYSICS, "REFERENCE_PHYSICS", "reference"),
                       "attitude": (ATTITUDE_PHYSICS, "ATTITUDE_PHYSICS", "attitude reference")}


def load_spec_terms(spec_dir=SPEC_DIR):
    """Every term of the spec as name -> (sensor, axis index, regressor function), the library
    names, and the presets (name -> state list, `base` + `terms` resolved)."""
    with open(os.path.join(spec_dir, "terms.toml"), "rb") as fh:
        raw = tomllib.load(fh)
    terms, library = {}, []
    for t in raw.get("term", []):
        name = t["name"]
        if t["sensor"] in MEASUREMENT_PHYSICS:
            # a measurement term: its physics is this file's own table, never the spec's H
            table, table_name, what = MEASUREMENT_PHYSICS[t["sensor"]]
            if name not in table:
                raise SpecTranslationError(
                    f"{what} term `{name}` is unknown to the checker's independent measurement model "
                    f"(it knows {' '.join(sorted(table))}): write its physics in {table_name}")
            terms[name] = (t["sensor"], None, None)
            if t.get("library", False):
                library.append(name)
            continue
        if t["sensor"] not in ("gyro", "accel") or t["axis"] not in ("x", "y", "z"):
            raise SpecTranslationError(f"term `{name}`: sensor `{t['sensor']}` / axis `{t['axis']}` unknown to the checker")
        physics = ACCEL_PHYSICS.get(name)
        if physics:
            # its physics is this file's own (ACCEL_PHYSICS); the spec's regressor is not read
            i, kind, what = physics
            if t["sensor"] != "accel" or "xyz".index(t["axis"]) != i:
                raise SpecTranslationError(f"term `{name}`: {what} of the {'xyz'[i]} accelerometer, "
                                           f"but the spec says {t['sensor']} {t['axis']}")
            terms[name] = ("accel", i, kind)
        else:
            terms[name] = (t["sensor"], "xyz".index(t["axis"]), translate_regressor(t["regressor"], name))
        if t.get("library", False):
            library.append(name)
    with open(os.path.join(spec_dir, "presets.toml"), "rb") as fh:
        raw_p = tomllib.load(fh)
    presets = {}
    for p in raw_p.get("preset", []):
        states = p["states"] if "states" in p else presets[p["base"]] + list(p.get("terms", []))
        presets[p["name"]] = states
    return terms, library, presets


try:
    TERMS, LIBRARY, PRESETS = load_spec_terms()
except (SpecTranslationError, OSError, KeyError, tomllib.TOMLDecodeError) as _e:
    sys.exit(f"verify_jacobians: spec {os.path.abspath(SPEC_DIR)}: {_e}")

NAV = ["phi_n", "phi_e", "phi_d", "dv_n", "dv_e", "dv_d", "dlat", "dlon", "dh"]
TERM_NAMES = list(TERMS)
ALL_STATES = NAV + TERM_NAMES
# the measurements, written independently:
# z = [dv_n, dv_e, dp_n, dp_e, dp_u, dvb_x, dvb_y, dvb_z, datt_n, datt_e, datt_d]
MEAS_ROWS = {"vel_ne": [0, 1], "pos_ne": [2, 3], "pos_h": [4], "vel_body": [5, 6, 7],
             "att_ref": [8, 9, 10]}
MEAS_STATES = {"vel_ne": ["dv_n", "dv_e"], "pos_ne": ["dlat", "dlon"], "pos_h": ["dh"],
               "vel_body": ["phi_n", "dv_n", "dv_d"], "att_ref": ["phi_n"]}

# ---------------------------------------------------------------- the nonlinear error dynamics
def build_jacobian_function():
    """CasADi function: point parameters -> (J_A [9 x (9+T)] at zero error, J_H, sparsity)."""
    p = ca.SX.sym("p", 20)  # lat, h, vn ve vd, roll pitch yaw, f_b(3), w_b(3), dw_b(3), df_b(3)
    lat, h = p[0], p[1]
    v = p[2:5]
    c = dcm_from_euler(p[5], p[6], p[7])
    f_b, w_b, dw_b, df_b = p[8:11], p[11:14], p[14:17], p[17:20]
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
        if sensor in MEASUREMENT_PHYSICS:
            continue
        if isinstance(reg, tuple) and reg[0] == "delay":
            # the accelerometer reads the signal of theta earlier
            def f_at(s):
                return f_b + s * df_b
            contrib = f_at(-theta[k])[axis] - f_b[axis]
        elif isinstance(reg, tuple):
            # an inner lever arm: the accelerometer at r = theta e_j
            r = ca.SX.zeros(3)
            r[reg[1]] = theta[k]
            contrib = (ca.cross(w_b, ca.cross(w_b, r)) + ca.cross(dw_b, r))[axis]
        else:
            contrib = theta[k] * reg(f_b, w_b, dw_b)
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
    # the GNSS fix: the antenna (IMU position + C l) on the trajectory at t + dt
    dt = 0
    lever = [0, 0, 0]
    for k, name in enumerate(TERM_NAMES):
        if TERMS[name][0] != "gnss":
            continue
        kind = GNSS_PHYSICS[name]
        if kind[0] == "time_offset":
            dt = dt + theta[k]
        else:
            lever[kind[1]] = lever[kind[1]] + theta[k]
    arm = ca.vertcat(*lever)
    c_arm = c @ arm
    v_arm = c @ ca.cross(w_b, arm)
    # the velocity reference: computed body velocity (C~^T (v + dv)) minus its reading
    mount = [0, 0, 0]
    dt_ref = 0
    scale = 0
    for k, name in enumerate(TERM_NAMES):
        if TERMS[name][0] == "reference":
            kind = REFERENCE_PHYSICS[name]
            if kind[0] == "mount":
                mount[kind[1]] = mount[kind[1]] + theta[k]
            elif kind[0] == "scale":
                scale = scale + theta[k]
            else:
                dt_ref = dt_ref + theta[k]
    c_rb = dcm_from_euler(mount[0], mount[1], mount[2])
    v_b = c.T @ v
    v_b_rate = cd_t.T @ v + c.T @ vd_t
    reading = c_rb.T @ (v_b + dt_ref * v_b_rate)
    reading[0] = (1 + scale) * reading[0]
    z_body = c_tilde.T @ (v + dv) - reading
    # the attitude reference: the rotation from its attitude to the computed one, as the small
    # rotation vector e of C~ (C_r^n)^T = exp(-[e x]) (computed minus reference)
    att_mount = [0, 0, 0]
    dt_att = 0
    for k, name in enumerate(TERM_NAMES):
        if TERMS[name][0] == "attitude":
            kind = ATTITUDE_PHYSICS[name]
            if kind[0] == "mount":
                att_mount[kind[1]] = att_mount[kind[1]] + theta[k]
            else:
                dt_att = dt_att + theta[k]
    c_rn = (c + dt_att * cd_t) @ dcm_from_euler(att_mount[0], att_mount[1], att_mount[2])
    rot = c_tilde @ c_rn.T
    z_att = -0.5 * ca.vertcat(rot[2, 1] - rot[1, 2], rot[0, 2] - rot[2, 0], rot[1, 0] - rot[0, 1])
    z = ca.vertcat(dv[0] - dt * vd_t[0] - v_arm[0],
                   dv[1] - dt * vd_t[1] - v_arm[1],
                   (rm0 + h) * (dlat - dt * latd_t) - c_arm[0],
                   (rn0 + h) * ca.cos(lat) * (dlon - dt * lond_t) - c_arm[1],
                   dh - dt * hd_t + c_arm[2],
                   z_body,
                   z_att)
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
    elif kind == 7 and "pos_ne" in out["h"]:
        # not a paper misprint: the radius mix-up of an H (R_N + h for R_M + h on dp_n)
        out["h"]["pos_ne"][0][idx["dlat"]] = rn
    elif kind == 8 and "vel_ne" in out["h"] and "dt_gnss" in idx:
        # a time offset's velocity rows without the Coriolis and transport terms (f_n alone)
        cm = np.array(dcm_from_euler(*[math.radians(e) for e in pt["euler_deg"]]))
        f_n = cm @ np.array(pt["f_b"], dtype=float)
        out["h"]["vel_ne"][0][idx["dt_gnss"]] = -float(f_n[0])
    elif kind == 9 and "vel_ne" in out["h"] and "lever_y" in idx:
        # a lever arm's velocity rows with the cross product reversed (l x w for w x l)
        col = idx["lever_y"]
        out["h"]["vel_ne"][0][col] = -out["h"]["vel_ne"][0][col]
    elif kind == 12 and "vel_body" in out["h"] and "mount_z" in idx:
        # a mounting's H with the sign reversed (the reference's yaw taken the other way)
        col = idx["mount_z"]
        out["h"]["vel_body"][1][col] = -out["h"]["vel_body"][1][col]
    elif kind == 13 and "vel_body" in out["h"]:
        # the attitude error entered with C~ = (I + [phi x]) C, the opposite convention
        for r in range(3):
            for s in ("phi_n", "phi_e", "phi_d"):
                out["h"]["vel_body"][r][idx[s]] = -out["h"]["vel_body"][r][idx[s]]
    elif kind == 14 and "vel_body" in out["h"] and "dt_ref" in idx:
        # a reference time offset without the navigation frame's rate (earth and transport)
        cm = np.array(dcm_from_euler(*[math.radians(e) for e in pt["euler_deg"]]))
        v = np.array(pt["v_ned"], dtype=float)
        w_in = np.array([OMEGA * c + ve / rn, -pt["v_ned"][0] / (rm0 + pt["h_m"]),
                         -OMEGA * s - ve * math.tan(lat) / rn])
        extra = cm.T @ np.cross(w_in, v)
        for r in range(3):
            out["h"]["vel_body"][r][idx["dt_ref"]] += float(extra[r])
    elif kind == 15 and "att_ref" in out["h"] and "att_mount_x" in idx:
        # an attitude reference's mounting entered through C's row, not its column (C^T m)
        col = idx["att_mount_x"]
        for r in range(3):
            out["h"]["att_ref"][r][col] = float(cm[0, r])
    elif kind == 16 and "att_ref" in out["h"] and "dt_att" in idx:
        # an attitude reference's time offset without the navigation frame's rate
        w_in = np.array([OMEGA * c + ve / rn, -pt["v_ned"][0] / (rm0 + pt["h_m"]),
                         -OMEGA * s - ve * math.tan(lat) / rn])
        for r in range(3):
            out["h"]["att_ref"][r][idx["dt_att"]] += float(w_in[r])
    elif kind == 11 and "tau_y" in idx:
        # an accelerometer delay with its sign reversed (a lead taken for a lag)
        for k, row in enumerate(["dv_n", "dv_e", "dv_d"]):
            if row in idx:
                a[idx[row]][idx["tau_y"]] = cm[k, 1] * pt["df_b"][1]
    elif kind == 10 and "size_x_y" in idx:
        # an off-axis inner lever arm with its tangential part reversed (r x dw for dw x r)
        dwz = pt["dw_b"][2]
        reg_wrong = w[0] * w[1] + dwz
        for k, row in enumerate(["dv_n", "dv_e", "dv_d"]):
            if row in idx:
                a[idx[row]][idx["size_x_y"]] = cm[k, 0] * reg_wrong


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
            "dw_b": [float(x) for x in rand_vec(30.0)],
            "df_b": [float(x) for x in rand_vec(300.0)],
        })
    return pts


def point_vector(pt):
    return [math.radians(pt["lat_deg"]), pt["h_m"], *pt["v_ned"],
            *[math.radians(v) for v in pt["euler_deg"]], *pt["f_b"], *pt["w_b"], *pt.get("dw_b", [0, 0, 0]),
            *pt.get("df_b", [0, 0, 0])]


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
    """Compares one model's generated A and H with CasADi's at every point. Returns (problems,
    worst absolute error, worst relative error, where the worst relative error is (a label like
    `A[phi_d][dlat]` or `H[pos_ne][dp_n][dlat]`, generated value, CasADi value), number of
    CasADi structural entries that cancel numerically)."""
    outs = run_sinsmodel(binary, model, points, runtime)
    worst_abs, worst_rel, worst_at = 0.0, 0.0, None
    problems = []
    states = outs[0]["states"]
    unknown = [s for s in states if s not in ALL_STATES]
    if unknown:
        return [f"states unknown to the independent model: {unknown}"], 0, 0, None, 0
    cols = [ALL_STATES.index(s) for s in states]
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
    unknown_meas = sorted(set(outs[0]["h"]) - set(MEAS_ROWS))
    if unknown_meas:
        problems.append(f"measurements unknown to the independent model (not checked): {unknown_meas}")
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
                        worst_rel = rel
                        worst_at = (f"A[{states[i]}][{states[j]}]", float(gen[i, j]), float(ref[i, j]))
                elif abs(ref[i, j]) > zero_tol or gen[i, j] != 0.0:
                    extra_nonzero.add((states[i], states[j]))
        for name, rows in MEAS_ROWS.items():
            if not all(s in states for s in MEAS_STATES[name]):
                continue
            if name not in out["h"]:
                problems.append(f"H {name} missing")
                continue
            hg = np.array(out["h"][name], dtype=float)
            hr = jh[rows][:, cols]
            if hg.shape != hr.shape:
                problems.append(f"H {name} has shape {hg.shape}, expected {hr.shape}")
                continue
            for c in range(hr.shape[0]):
                # an entry the generator leaves at zero where CasADi holds a rounding residue of
                # products that cancel analytically (the attitude reference's C C^T: ~1e-16 of
                # the row's unit entries) is a zero; anything larger still counts
                zero_tol = 1e-14 * max(1.0, float(np.max(np.abs(hr[c]))))
                for j in range(n):
                    d = abs(hg[c, j] - hr[c, j])
                    worst_abs = max(worst_abs, d)
                    if d == 0.0 or (hg[c, j] == 0.0 and abs(hr[c, j]) <= zero_tol):
                        continue
                    rel = d / max(abs(hr[c, j]), 1e-12)
                    if rel > worst_rel:
                        worst_rel = rel
                        worst_at = (f"H[{name}][{c}][{states[j]}]", float(hg[c, j]), float(hr[c, j]))
    if extra_nonzero:
        problems.append(f"CasADi non-zeros outside the generated pattern: {sorted(extra_nonzero)[:8]}")
    if worst_rel > tol:
        label, g, r = worst_at
        problems.append(f"worst relative error {worst_rel:.3e} > {tol:.1e} at {label}: generated {g:.12g}, CasADi {r:.12g}")
    cancelled = len(cas_struct - gen_struct)
    return problems, worst_abs, worst_rel, worst_at, cancelled


def default_models():
    """Every spec preset with and without the vertical channel, and the largest preset with every
    spec term it lacks (with and without vertical): every term of the spec is checked."""
    models = []
    for name in PRESETS:
        models += [name, f"{name}+vertical"]
    largest = max(PRESETS, key=lambda k: len(PRESETS[k]))
    rest = [t for t in TERM_NAMES if t not in PRESETS[largest]]
    if rest:
        models += [f"{largest}+{'+'.join(rest)}", f"{largest}+vertical+{'+'.join(rest)}"]
    return models


def label_of(model):
    parts = model.split("+")
    if len(parts) <= 4:
        return model
    head = [p for p in parts[:2] if p == parts[0] or p == "vertical"]
    return "+".join(head) + f"+<{len(parts) - len(head)} terms>"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", required=True, help="path of the sinsmodel binary")
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--seed", type=int, default=20131)
    ap.add_argument("--tol", type=float, default=1e-9, help="relative tolerance")
    ap.add_argument("--models", nargs="*", default=None)
    ap.add_argument("--corrupt", type=int, default=0, help="apply paper misprint K (1-6) to the generated A, or 7: R_N for R_M in H[pos_ne], 8: a time offset's velocity H without Coriolis, 9: a lever arm's velocity H reversed, 10: an off-axis inner lever arm's tangential part reversed, 11: an accelerometer delay's sign reversed, 12: a reference mounting's yaw reversed in H[vel_body], 13: the attitude error's sign reversed in H[vel_body], 14: a reference time offset's H without the navigation frame's rate, 15: an attitude reference's mounting through C's row, not its column, 16: an attitude reference's time offset without the navigation frame's rate; the check must fail")
    args = ap.parse_args()

    models = args.models or default_models()
    fun, x0, sparsity = build_jacobian_function()
    rng = np.random.default_rng(args.seed)
    points = random_points(args.points, rng)
    failed = False
    overall_abs, overall_rel = 0.0, 0.0
    for model in models:
        label = label_of(model)
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
    checked = {s for m in models for s in m.split("+")[1:] if s in TERMS}
    checked |= {s for m in models for s in PRESETS.get(m.split("+")[0], []) if s in TERMS}
    print(f"spec terms checked: {len(checked)} of {len(TERMS)}"
          + ("" if len(checked) == len(TERMS) else f" (not checked: {sorted(set(TERMS) - checked)})"))
    print(f"points {len(points)}, models {len(models)}: worst absolute error {overall_abs:.3e}, "
          f"worst relative error {overall_rel:.3e} (tolerance {args.tol:.1e} relative)")
    print("FAILED" if failed else "PASSED")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
