"""A layout of disks in a box (floor y = 0, side walls x = 0 and x = width) written both as the
CSV that `bench_dem --siconos N --csv` writes, which bench/siconos_deposit.py rebuilds in
Siconos 4.4, and as a MULTICOR deck of the same problem (one material, Coulomb friction,
Newton restitution, the Siconos criterion): the tests that compare the two codes."""
import numpy as np


def write_box_layout(work, stem, disks, width, *, rho, g, mu, e, tol, max_sweeps, h, steps, interval,
                     title, time_extra=""):
    """Write work/stem.csv and work/stem.dat for disks (rows x, y, r) [m] of density rho
    [kg/m^3] under gravity g [m/s^2]; returns (csv, deck). time_extra: more [time] lines."""
    csv = work / f"{stem}.csv"
    with open(csv, "w", encoding="ascii") as f:
        f.write(f"# MULTICOR deposit against Siconos: {len(disks)} disks; box: floor y = 0, side walls "
                f"x = 0 and x = {width:.16e} m\n# {title}\nx,y,radius,mass,inertia\n")
        for x, y, r in disks:
            m = rho * np.pi * r * r
            f.write(f"{x:.17e},{y:.17e},{r:.17e},{m:.17e},{0.5 * m * r * r:.17e}\n")
    top = max(y + r for _, y, r in disks) + 0.05
    lines = "\n".join(f"disk = {x:.17e} {y:.17e} {r:.17e} 1" for x, y, r in disks)
    deck = work / f"{stem}.dat"
    deck.write_text(f"""[run]
title = {title}
analysis = dynamic

[particles]
material = 1 {rho}
gravity = 0 -{g}
{lines}

[walls]
wall = 0 0 {width:.17e} 0
wall = 0 0 0 {top:.17e}
wall = {width:.17e} 0 {width:.17e} {top:.17e}

[contacts]
law = 1 1 {mu} {e} 0
alert = 5e-3

[solver]
tolerance = {tol}
criterion = siconos
max_sweeps = {max_sweeps}

[time]
step = {h}
end = {h * steps}
{time_extra}
[output]
interval = {interval}
""")
    return csv, deck
