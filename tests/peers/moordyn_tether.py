"""MoorDyn 2.7 (PyPI `moordyn`) run of a tethered aerostat in air, for
tests/peer_moordyn.rs.

Reads a JSON case on stdin and prints a JSON time history on stdout.
Air maps onto MoorDyn's water as in the project's notes: fluid density
rho_air, a deep "seabed" (the winch is a fixed point 3000 m down), the
aerostat a free point of volume (F/g + m)/rho_air and drag area C_D A, the
line's mass raised by rho_air pi d^2/4 (its buoyancy cancelled), no added
mass on the line. The wind is set on every node and point each coupling
step through MoorDyn's external kinematics (WaveKin = 1), spatially uniform:
u(t) = mean * min(1, t/ramp) + (A/2)(1 - cos(2 pi (t - t0)/T)) on [t0, t0+T];
the fluid acceleration is passed as zero (no Froude-Krylov force, as in the
tetherplan model). Tensions are the end-node forces |Fnet| of the line.
"""
import json
import math
import os
import sys
import tempfile
import time

import cmoordyn
import moordyn

DEPTH = 3000.0


def norm(v):
    return math.sqrt(sum(x * x for x in v))


def wind(c, t):
    u = c["mean_m_s"] * (min(1.0, t / c["ramp_s"]) if c["ramp_s"] > 0 else 1.0)
    tau = t - c["gust_start_s"]
    if 0.0 < tau < c["gust_duration_s"]:
        u += 0.5 * c["gust_amplitude_m_s"] * (1.0 - math.cos(2.0 * math.pi * tau / c["gust_duration_s"]))
    return u


def rate_at(c, t):
    """The winch rate (m/s): linear in the table `rate_points` [[t, rate], ...]
    (held after it), zero from `stop_time_s` on; none without a table."""
    pts = c.get("rate_points")
    if not pts or t >= c.get("stop_time_s", float("inf")):
        return 0.0
    if t >= pts[-1][0]:
        return pts[-1][1]
    for (t0, r0), (t1, r1) in zip(pts, pts[1:]):
        if t0 <= t < t1:
            return r0 + (r1 - r0) * (t - t0) / (t1 - t0)
    return 0.0


def length_at(c, t):
    """The unstretched length at t (m): the rate integrated exactly."""
    pts = c.get("rate_points")
    length = c["length_m"]
    if not pts:
        return length
    t = min(t, c.get("stop_time_s", float("inf")))
    knots = [p[0] for p in pts if p[0] < t] + [t]
    for a, b in zip(knots, knots[1:]):
        length += 0.5 * (rate_at(c, a) + rate_at(c, b - 1e-12 * max(1.0, b))) * (b - a)
    return length


def main():
    c = json.load(sys.stdin)
    g = c["gravity_m_s2"]
    rho = c["air_density_kg_m3"]
    d = c["diameter_m"]
    mass = c["mass_per_length_kg_m"] + rho * math.pi * d * d / 4.0
    volume = (c["net_buoyancy_n"] / g + c["aerostat_mass_kg"]) / rho
    length = c["length_m"]
    stretch = (c["net_buoyancy_n"] * length - 0.5 * c["mass_per_length_kg_m"] * g * length**2) / c["axial_stiffness_n"]
    z_top = -DEPTH + length + stretch
    text = f"""--------------------- MoorDyn Input File ------------------------------------
tethered aerostat in air (tetherplan peer check)
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA     BA/-zeta    EI    Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)    (N-s/-)   (N-m^2) (-)    (-)    (-)     (-)
tether     {d}   {mass:.10g}   {c["axial_stiffness_n"]}   {c["internal_damping_n_s"]}   0   {c["normal_drag_coefficient"]}   0.0   0.0   0.0
---------------------- POINTS --------------------------------
ID  Attachment   X     Y     Z    Mass   Volume  CdA   CA
(#)   (-)       (m)   (m)   (m)   (kg)   (m^3)  (m^2)  (-)
1    Fixed      0     0   {-DEPTH}    0      0      0     0
2    Free       0     0   {z_top:.10g}   {c["aerostat_mass_kg"]}   {volume:.10g}   {c["aerostat_drag_area_m2"]}   {c["added_mass_coefficient"]}
---------------------- LINES --------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)      (-)
1    tether      1        2       {length}      {c["segments"]}       -
---------------------- OPTIONS -----------------------------------------
0        writeLog
{c["md_time_step_s"]}    dtM
{c.get("md_scheme", "RK2")}  tScheme
{g}     g
{rho}    rho
{DEPTH}     WtrDpth
1        WaveKin
0        Currents
{c.get("md_tmax_ic_s", 0.0)}        TmaxIC
{c.get("md_thresh_ic", 0.001)}        threshIC
1        disableOutput
1        disableOutTime
--------------------- need this line ------------------
"""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "aerostat.dat")
        with open(path, "w") as f:
            f.write(text)
        system = moordyn.Create(path)
        moordyn.SetVerbosity(system, moordyn.LEVEL_ERR)
        moordyn.Init(system, [], [])
        moordyn.ExternalWaveKinInit(system)
        n = len(moordyn.ExternalWaveKinGetCoordinates(system))
        line = moordyn.GetLine(system, 1)
        point = moordyn.GetPoint(system, 2)
        segments = c["segments"]
        dt = c["coupling_step_s"]
        steps = int(round(c["duration_s"] / dt))
        out = {"time_s": [], "winch_tension_n": [], "top_tension_n": [], "aerostat_downwind_m": [], "aerostat_altitude_m": []}

        def record(t):
            pos = moordyn.GetPointPos(point)
            out["time_s"].append(t)
            out["winch_tension_n"].append(norm(moordyn.GetLineNodeForce(line, 0)))
            out["top_tension_n"].append(norm(moordyn.GetLineNodeForce(line, segments)))
            out["aerostat_downwind_m"].append(pos[0])
            out["aerostat_altitude_m"].append(pos[2] + DEPTH)

        t = 0.0
        record(t)
        cpu = time.process_time()
        zeros = [0.0] * (3 * n)
        # A changing length: the rate is set (only when it changes) every
        # `rate_update_s` at most, as the mean rate of the chunk, so the
        # length follows the schedule exactly at the chunk ends.
        chunks = max(1, int(math.ceil(dt / c.get("rate_update_s", dt) - 1e-9))) if c.get("rate_points") else 1
        rate_set = None
        for i in range(steps):
            u = wind(c, t + 0.5 * dt)
            vel = [0.0] * (3 * n)
            vel[0::3] = [u] * n
            cmoordyn.ext_wave_set(system, vel, zeros, t)
            for k in range(chunks):
                ta = i * dt + k * dt / chunks
                tb = i * dt + (k + 1) * dt / chunks
                if c.get("rate_points"):
                    # Rounded: a constant rate is set once, not every chunk.
                    rate = round((length_at(c, tb) - length_at(c, ta)) / (tb - ta), 9)
                    if rate != rate_set:
                        moordyn.SetLineUnstretchedLengthVel(line, rate)
                        rate_set = rate
                moordyn.Step(system, [], [], ta, tb - ta)
            t = (i + 1) * dt
            record(t)
            if c.get("rate_points"):
                out.setdefault("length_m", []).append(moordyn.GetLineUnstretchedLength(line))
        out["cpu_s"] = time.process_time() - cpu
        moordyn.Close(system)
    # MoorDyn writes to stdout too: the answer is the last line.
    sys.stdout.write("\n" + json.dumps(out) + "\n")
    sys.stdout.flush()
    # moordyn 2.7.2's C extension drops a reference to None on calls that
    # return nothing (SetLineUnstretchedLengthVel, every rate change):
    # after many, the interpreter's finalisation aborts on it. The answer
    # is written: leave without finalising.
    os._exit(0)


if __name__ == "__main__":
    main()
