"""
What a hand feels stroking a rock profile
=========================================

Haptic rendering turns a profile into forces on a hand: a virtual stylus rides the
surface, and once per servo period (1 ms) the contact model sends the force to the
device. In the quasi-static model of Costa and Cutkosky's experiment the normal force
is a stiff spring, F_y = K (h - y) while the hand's height y is below the surface
height h (K = 1.28 N/mm), and the lateral force F_x = -F_y h' resists climbing the
local slope h'.

Here the joystick is replaced by rough's simulated hand: a 150 g mass with 2 N·s/m of
damping that presses down with 1 N while it strokes along the profile at a constant
speed. We stroke the sample profile at 20, 60 and 120 mm/s.
"""

import matplotlib.pyplot as plt
import numpy as np

import rough

profile = rough.read(rough.sample("rock-profile.tsv"))

# %%
# The slope RMS of a fractal profile grows as the spacing shrinks, as Δx^-(D-1), so
# the lateral force depends on the resolution at which the profile is rendered. The
# paper stored its profiles at 0.1545 mm; we resample to that spacing first.

rendered = rough.resample(profile, 0.1545e-3)
track = rough.Track.from_surface(rendered)
speeds = (0.02, 0.06, 0.12)  # m/s
runs = {speed: rough.simulate(track, speed) for speed in speeds}

for speed, run in runs.items():
    stats = rough.forces(run)
    stroke = track.length / speed  # s
    print(
        f"{speed * 1e3:3.0f} mm/s: F_y std {stats['F_y_std']:.3f} N, max {stats['F_y_max']:.2f} N; "
        f"F_x RMS {stats['F_x_rms']:.3f} N; out of contact {100 * stats['out_of_contact']:.1f} % "
        f"({stats['out_of_contact'] * stroke * 1e3:.0f} ms of {stroke:.2f} s)"
    )

# %%
# The normal force against position
# ---------------------------------
#
# Each run's trace holds one row per tick: time, the hand's position x and height
# y_i, the surface height h, the forces and whether the stylus touched. Grey spans
# mark ticks out of contact. The mean of F_y is the 1 N press.
#
# At 20 mm/s the hand follows the surface and F_y stays near 1 N. Faster, the same
# bumps arrive at higher frequencies and the hand's inertia shows. The hand on the
# contact spring resonates at √(K/m)/2π ≈ 15 Hz, so the wavelength it responds to most,
# speed / 15 Hz, grows with speed: 1.4 mm at 20 mm/s, 8 mm at 120 mm/s. A fractal
# profile has more relief at longer wavelengths, so the spread of F_y grows with speed,
# about fourfold here, and at 120 mm/s the hand flies off the crests.

fig, axes = plt.subplots(len(speeds) + 1, 1, figsize=(8, 8), sharex=True)
axes[0].plot(rendered.positions() * 1e3, rendered.heights * 1e3, color="0.3", lw=0.8)
axes[0].set_ylabel("h (mm)")
axes[0].set_title("profile at 0.1545 mm, and the normal force on the hand", fontsize="medium")
for ax, (speed, run) in zip(axes[1:], runs.items()):
    trace = run.trace
    x = trace["x"] * 1e3  # mm
    ax.fill_between(x, 0, 1, where=~trace["contact"], color="0.85", transform=ax.get_xaxis_transform(), lw=0)
    ax.plot(x, trace["F_y"], color="tab:blue", lw=0.7)
    ax.axhline(1.0, color="tab:red", lw=0.8, ls="--")
    ax.set_ylim(-0.1, 2.8)
    ax.set_ylabel("F_y (N)")
    ax.text(0.01, 0.85, f"{speed * 1e3:g} mm/s", transform=ax.transAxes, fontsize="small")
axes[-1].set_xlabel("x (mm)")
fig.tight_layout()
plt.show()

# %%
# A probe between the hand and the rock
# -------------------------------------
#
# A hand that strokes the rock through a probe does not feel the profile itself but
# the path of the probe's tip: a round tip of radius r cannot enter valleys narrower
# than itself and rounds every crest. :func:`rough.traced <rough.metrology.tip.traced>`
# computes that path (the grey dilation of the profile by the tip). We apply a 0.5 mm
# tip, about a fingernail, to the profile as measured (30.9 µm), before resampling.

tip = rough.traced(profile, 0.5e-3)

fig, ax = plt.subplots(figsize=(8, 3))
x = profile.positions() * 1e3  # mm
stretch = (x >= 22) & (x <= 25)
ax.plot(x[stretch], profile.heights[stretch] * 1e3, color="0.3", lw=0.8, label="profile")
ax.plot(x[stretch], tip.heights[stretch] * 1e3, color="tab:orange", lw=1.2, label="path of the tip's apex")
apex = np.argmin(abs(x - 23.6))
ax.add_patch(plt.Circle((x[apex], tip.heights[apex] * 1e3 + 0.5), 0.5, fill=False, color="tab:orange", ls=":"))
ax.set_aspect("equal")
ax.set_xlabel("x (mm)")
ax.set_ylabel("height (mm)")
ax.legend(fontsize="small", loc="lower left")
fig.tight_layout()
plt.show()

# %%
# The tip leaves Rq nearly unchanged (it lives in the long wavelengths) but lowers the
# slopes, and with them the lateral force F_x = -F_y h' that carries the slopes to the
# hand. How much depends on the spacing at which the profile is rendered: resampling
# to 0.1545 mm has already removed most of the short wavelengths the tip bridges.

print(f"Rq: {rough.parameters(profile)['Rq'] * 1e3:.3f} mm bare, {rough.parameters(tip)['Rq'] * 1e3:.3f} mm traced")
for name, surface in (("bare", profile), ("0.5 mm tip", tip)):
    for felt in (surface, rough.resample(surface, 0.1545e-3)):
        felt_track = rough.Track.from_surface(felt)
        slope_rms = np.sqrt(np.mean(felt_track.slopes**2))
        stats = rough.forces(rough.simulate(felt_track, 0.06))
        print(
            f"{name:10s} rendered at {felt.spacing[0] * 1e3:.4f} mm: slope RMS {slope_rms:.3f}, "
            f"F_x RMS at 60 mm/s {stats['F_x_rms']:.3f} N"
        )
