#!/usr/bin/env python3
"""Writes the two-grain verification scenes of the flat-joint memo, section 2.1 (units: SI).

Two granite grains (E = 29 GPa, nu = 0.15, rho = 2650 kg/m^3, R = 6.25 mm so that
lambda = 0.8 gives a 5 mm bond/joint radius) touch along y. Both are fixed and moved:
axial: grain 2 moves +y by 1 mm; twist (3D): grain 2 turns 0.2 rad about y;
bend: the grains turn by -+0.2 rad about the t axis (3D: t = -z; 2D: about z, so that the
relative bend rotation theta_bs = +0.4 rad). 1000 steps of 1 us.
"""
import json, os

E, NU, L = 29e9, 0.15, 12.5e-3
KN, KS = E / L, E / (2 * (1 + NU) * L)
HERE = os.path.dirname(os.path.abspath(__file__))


def scene(dim, model, props, case, tag):
    R = 6.25e-3
    v2, w1, w2 = [0, 0, 0], [0, 0, 0], [0, 0, 0]
    if case == "axial":
        v2 = [0, 1.0, 0]
    elif case == "twist":
        w2 = [0, 200.0, 0]
    else:  # bend
        if dim == 3:
            w1, w2 = [0, 0, 200.0], [0, 0, -200.0]  # about t = -z: theta_bt = +0.4
        else:
            w1, w2 = [0, 0, 200.0], [0, 0, -200.0]  # theta_z = -0.4: theta_bs = +0.4
    def ball(i, pos, v, w):
        b = {"id": i, "position": pos[:dim], "radius": R, "density": 2650,
             "velocity": v[:dim], "fix": "all"}
        b["spin"] = w[2] if dim == 2 else w
        return b
    return {
        "description": f"Memo 2.1 two-grain test, {model} {dim}D, {case} ({tag}). Units: SI.",
        "dimension": dim,
        "local_damping": 0.7,
        "timestep": 1e-6,
        "balls": [ball(1, [0, 0, 0], [0, 0, 0], w1), ball(2, [0, 2 * R, 0], v2, w2)],
        "contact_models": [{"between": "ball-ball", "model": model, "properties": props}],
        "run": {"cycles": 1000},
    }


def pb():
    return {"kn": 0, "ks": 0, "pb_rmul": 0.8, "pb_mcf": 1.0, "pb_kn": KN, "pb_ks": KS,
            "pb_ten": 1e20, "pb_coh": 1e20, "pb_fa": 0,
            # bond pieces up to 1 nm apart: "just touching" is exact only up to round-off
            "bond": 1e-9}


def fj(dim, nr, nal=None, exact=False):
    p = {"fj_Nr": nr, "fj_rmul": 0.8, "fj_gap0": 0, "fj_kn": KN, "fj_ks": KS, "fj_fric": 0,
         "fj_ten": 1e20, "fj_coh": 1e20, "fj_fa": 0, "bond": True}
    if dim == 3:
        p["fj_Nal"] = nal
    if exact:
        p["fj_exact"] = True
    return p


def write(name, data):
    with open(os.path.join(HERE, name + ".json"), "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")


for case in ("axial", "twist", "bend"):
    write(f"two_grain_pb_3d_{case}", scene(3, "linearpbond", pb(), case, "parallel bond"))
    for nr, nal in ((2, 8), (3, 16), (4, 24)):
        write(f"two_grain_fj_3d_{case}_{nr}x{nal}",
              scene(3, "flatjoint", fj(3, nr, nal), case, f"Nr={nr}, Nal={nal}"))
        write(f"two_grain_fjexact_3d_{case}_{nr}x{nal}",
              scene(3, "flatjoint", fj(3, nr, nal, True), case, f"exact, Nr={nr}, Nal={nal}"))
for case in ("axial", "bend"):
    write(f"two_grain_pb_2d_{case}", scene(2, "linearpbond", pb(), case, "parallel bond"))
    write(f"two_grain_fj_2d_{case}", scene(2, "flatjoint", fj(2, 4), case, "Nr=4"))


def interlocked(dim, exact=False):
    """Memo 2.2: a central grain and four neighbours (+-x, +-y), unbonded frictionless flat
    joints. Stage 1 turns the central grain by 0.01 rad about z with everything fixed; stage 2
    stops it and frees the neighbours' rotations (local damping 0.7)."""
    R = 6.25e-3
    props = fj(dim, 4 if dim == 2 else 2, 8 if dim == 3 else None, exact)
    props.update({"bond": False, "fj_ten": 0, "fj_coh": 0})
    def ball(i, x, y):
        return {"id": i, "position": [x, y] if dim == 2 else [x, y, 0], "radius": R,
                "density": 2650, "fix": "all"}
    spin = 10.0 if dim == 2 else [0, 0, 10.0]
    still = 0.0 if dim == 2 else [0, 0, 0]
    free = ["rz"] if dim == 2 else ["rx", "ry", "rz"]
    return {
        "description": f"Memo 2.2 interlocked grain, {dim}D{' exact' if exact else ''}: turn the "
                       "centre, then release the neighbours' rotations. Units: SI.",
        "dimension": dim,
        "local_damping": 0.7,
        "timestep": 1e-6,
        "balls": [ball(1, 0, 0), ball(2, 2 * R, 0), ball(3, 0, 2 * R), ball(4, -2 * R, 0),
                  ball(5, 0, -2 * R)],
        "contact_models": [{"between": "ball-ball", "model": "flatjoint", "properties": props}],
        "run": [
            {"cycles": 1000, "set": [{"ball": 1, "spin": spin}]},
            {"cycles": 20000, "set": [{"ball": 1, "spin": still}] +
                                     [{"ball": i, "free": free} for i in (2, 3, 4, 5)]},
        ],
    }


write("interlocked_2d", interlocked(2))
write("interlocked_3d", interlocked(3))
write("interlocked_3d_exact", interlocked(3, True))


def joint_slide(mu, coh=None):
    """A block (ball with fixed rotations) resting on a fixed ball across a smooth joint that
    dips 30 degrees (dip direction 90: n_j = (0.5, 0, 0.866)); gravity -z. Unbonded with
    mu = 0.3 < tan 30 it slides with a = g (sin 30 - mu cos 30); with mu = 0.7 it holds."""
    R = 6.25e-3
    props = {"sj_kn": 1e9, "sj_ks": 1e9, "sj_fric": mu, "dip": 30, "ddir": 90}
    if coh is not None:
        props.update({"bond": 1e-9, "sj_coh": coh, "sj_ten": 1e6})
    return {
        "description": f"Smooth-joint block slide, mu = {mu}" + (f", bonded, c = {coh} Pa" if coh else "") + "."
                       " Units: SI.",
        "dimension": 3,
        "gravity": [0, 0, -9.81],
        "local_damping": 0,
        "timestep": 2e-6,
        "balls": [{"id": 1, "position": [0, 0, 0], "radius": R, "density": 2650, "fix": "all"},
                  {"id": 2, "position": [0, 0, 2 * R], "radius": R, "density": 2650,
                   "fix": ["rx", "ry", "rz"]}],
        "contact_models": [{"between": "ball-ball", "model": "smoothjoint", "properties": props}],
        "run": {"cycles": 50000},
        "history": {"every": 1000, "columns": ["time", "ball/2/position/x", "ball/2/position/z",
                                               "energy/slip", "events/slip_change"]},
    }


write("smooth_joint_slide", joint_slide(0.3))
write("smooth_joint_hold", joint_slide(0.7))
write("smooth_joint_bonded_strong", joint_slide(0.3, 1e6))
write("smooth_joint_bonded_weak", joint_slide(0.3, 50.0))
