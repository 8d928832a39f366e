"""The self-test effects of the plants added since session 22 (cyclopebax, snakedent, planetwist,
notchclutch, pronyring, wormeyelet), each in its own physics: keywords and knob factors.

Sized by the rule of :mod:`tsmd.gap.preset_effects` (the earlier plants' module, split off at
its size guide); :mod:`tsmd.gap.presets` builds the presets.
"""

from __future__ import annotations

CYCLOPEBAX_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling": 3.0},
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The cyclopebax plant's effect keywords, sized before any diagnosis (tip RMSE effect on minus
off, units 1 / 2, noise-free, 120 s of the experiment motion at 50 Hz): the other plane's
neutral-axis take-up on every rope four times the section's own (``coupling`` 3.0, the plant's
keyword added for this preset; x2 0.49 / 0.49, x3 0.97 / 0.93, x6 2.99 / 2.85), 1.52 / 1.44 deg
(the others' coupling 1.5 deg); a 120 deg sheath bend (added to the coil lumen's wrap), 3.99 /
4.73 deg (60 deg 1.85 / 2.31), inside the others' 1.1-12.8 deg. Its laws read the knob angle
only (the reducer's and the brake's presliding are in angle, the lumen friction is Coulomb and
no law takes the step's time) and nothing moves at a held knob (the ropes' set follows the
tension, not time): rate and creep are not run. "None" is the nominal physics as written
(docs/gap.md "Session 22")."""

CYCLOPEBAX_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Compliance on cyclopebax as a factor on the unit's knob constants, sized before any
diagnosis (same criterion): the steel rope's EA halved, 4.19 / 4.31 deg (units 1 / 2)."""

CYCLOPEBAX_MAX_STEP_S = 0.0
"""No finer stepping: the nominal-scatter unit's tip lies 0.19 deg RMS from 0.25 ms steps at 20
ms, and no closer at 4 ms (0.17), 1 ms (0.16) or 0.5 ms (0.12; unit 1, 120 s of the experiment
motion): its rope contacts slip in events whose timing moves with the step, as a real catheter's
would with the drive's own timing; a finer step buys nothing."""


SNAKEDENT_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling": 4.5},
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The snakedent plant's effect keywords, sized before any diagnosis (tip RMSE effect on minus
off, units 1 / 2, noise-free, 120 s of the experiment motion at 50 Hz): the other plane's
take-up on every rope 5.5 times the vertebrae's own (``coupling`` 4.5, the plant's keyword
added for this preset: rope holes set off their plane; x3 0.64 / 0.87, x5 1.21 / 1.50, x6 1.48
/ 1.87, the take-up removed altogether 0.31 / 0.57), 1.34 / 1.68 deg (the others' coupling 1.5
deg); a 120 deg sheath bend (added to every lumen contact's wrap), 1.52 / 1.32 deg (60 deg 0.70
/ 0.61), inside the others' 1.1-12.8 deg. Its laws read the knob angle only (the lumen
contacts and the joints' friction band are Coulomb, the knob seal's tanh saturates at 2 deg/s
and acts on the motor: x3 moves the tip 0.000 deg, the current 7-8 mA RMS) and nothing moves
at a held knob: rate and creep are not run. The detent and the load-grown joint friction are
base physics; "none" is the nominal physics as written (docs/gap.md "Session 23")."""

SNAKEDENT_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Compliance on snakedent as a factor on the unit's knob constants, sized before any diagnosis
(same criterion): the steel rope's EA halved, 3.61 / 3.44 deg (units 1 / 2)."""

SNAKEDENT_MAX_STEP_S = 0.0
"""No finer stepping: the nominal-scatter unit's tip lies 0.014 deg RMS (0.32 max) from 0.25 ms
steps at 20 ms, 0.011 (0.07) at 4 ms (unit 1, 120 s of the experiment motion): quasi-static."""


PLANETWIST_EFFECTS: dict[str, dict[str, float]] = {
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The planetwist plant's one effect keyword: a 120 deg sheath bend (added to every lumped lumen
contact's wrap), 1.84 / 1.73 deg of tip (tip RMSE effect on minus off, units 1 / 2, noise-free,
120 s of the experiment motion at 50 Hz; 60 deg 0.62 / 0.61), inside the others' 1.1-12.8 deg.
Its laws read the knob angle only at the tip (the stage's driving/back-driven loss and the
handle's friction turn round with the knob speed but act on the motor: the same path 8 times as
fast moves the tip 0.000 deg, flow off; handle friction x3 moves the current 10-11 mA RMS, the
tip 0.000) and nothing drifts at a held knob (75 deg held 60 s: the tip's five-beat mean moves
0.003 deg, the heart's pulse 0.03 deg peak to peak): rate and creep are not run. The stage's
play, the planets' load sharing, the swivel crimps, the section's stiffening with the total bend
and the pulsing flow are base physics; "none" is the nominal physics as written (docs/gap.md
"Session 24")."""

PLANETWIST_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"cross_takeup": 6.0},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Planetwist effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, units 1 / 2): the other plane's bend taking up six times the unit's share of both
ropes (``cross_takeup``, the plant's constant that reads the other plane only: rope lumens set
off their plane), 1.67 / 1.28 deg (x5 1.38 / 1.06, x5.5 1.52 / 1.17, x6.5 1.81 / 1.38, x7 1.94 /
1.48; the take-up removed altogether 0.41 / 0.31; the others' coupling 1.5 deg); the strand's EA
halved (its twist coupling and torsion scale with it), 5.06 / 5.41 deg."""

PLANETWIST_MAX_STEP_S = 0.0
"""No finer stepping: the nominal-scatter unit's tip lies 0.039 deg RMS (0.12 max) from 0.25 ms
steps at 20 ms, 0.007 (0.02) at 4 ms (unit 1; unit 2 0.024 / 0.005): quasi-static, the flow's
pulse sampled."""


NOTCHCLUTCH_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling": 0.2},
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The notchclutch plant's effect keywords, sized before any diagnosis (tip RMSE effect on minus
off, units 1 / 2, noise-free, 120 s of the experiment motion at 50 Hz): the other plane's bend
taking up both tendons (``coupling`` 0.2, the plant's keyword added for this preset: lumens set
off their plane, 0.2 x offset x other^2 / 2 mm), 1.66 / 1.13 deg (0.1 0.78 / 0.54, 0.25 2.16 /
1.47, 0.4 3.99 / 2.75; the others' coupling 1.5 deg); a 120 deg sheath bend (added to every lumen
contact's wrap), 4.31 / 0.78 deg (60 deg 0.47 / 0.36), inside the others' 1.1-12.8 deg on unit 1.
The slip clutch, the braid's toe, the liner's soak and Stribeck rise, the notches' closure and
the tip's friction on the wall are base physics; "none" is the nominal physics as written
(docs/gap.md "Session 25")."""

NOTCHCLUTCH_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"rate_stiffening": 20.0},
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"soak_time_s": 5.0},
}
"""Notchclutch effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, units 1 / 2): rate is the braid's stiffening with strain rate twenty times the
unit's (its one speed law that reaches the tip; the liner's Stribeck rise x4 moves it 0.17 /
0.14 deg), 1.67 / 1.49 deg (x10 1.17 / 1.01, x15 1.48 / 1.30; the others' rate 1.1-1.9 deg);
the braid's EA halved, 4.57 / 4.41 deg; creep (read as drift: time in the run) is the liner
soaking five times as slowly (40 -> 200 s, a coating that hydrates late: its friction and drag
move through the whole run instead of its first minute), 0.37 / 0.26 deg (x10 0.47 / 0.32; the
others' creep 0.35-0.43 deg). Nothing else at the tip moves at a held knob."""

NOTCHCLUTCH_MAX_STEP_S = 0.0
"""No finer stepping: unit 1's tip lies 0.22 deg RMS (2.3 max) from 0.25 ms steps at 20 ms and
0.17 (2.1) at 4 ms (unit 2 0.20 / 0.16; 120 s of the experiment motion): the rate laws use the
previous step's strain rate and film speed and the wall's hold sticks where the step leaves it,
so a finer step buys little, as on cyclopebax."""


PRONYRING_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling": 0.6},
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The pronyring plant's effect keywords, sized before any diagnosis (tip RMSE effect on minus
off, units 1 / 2, noise-free, 120 s of the experiment motion at 50 Hz): the other plane's bend
taking up both ropes (``coupling`` 0.6, the plant's keyword added for this preset: rope lumens
set off their plane at the ring, 0.6 x offset x other^2 / 2 mm), 1.13 / 1.64 deg (0.4 0.72 /
1.01, 0.7 1.36 / 2.02; the others' coupling 1.5 deg; the ring's anchor clocking x8 gives 1.09 /
0.76 deg but turns the ring's own tilt as well, 0.24-0.29 deg with the other knob held at 0); a
120 deg sheath bend (the shaft's anterior-posterior bend and every rope's wrap), 5.76 / 5.96 deg
(60 deg 2.99 / 3.05), inside the others' 1.1-12.8 deg. The section's Prony relaxation, the
ring's tilt, set-back and seat friction, the liner's load-dependent friction and the breathing
are base physics; "none" is the nominal physics as written (docs/gap.md "Session 26")."""

PRONYRING_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"prony_fast_Nmm_per_rad": 2.5},
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"prony_slow_Nmm_per_rad": 1.75},
}
"""Pronyring effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, units 1 / 2): rate is the section's fast Prony branch (3 s) 2.5 times as stiff (the
section stiffer the faster it is bent), 1.34 / 1.76 deg (x2 0.93 / 1.22, x3 1.73 / 2.27; the
others' rate 1.1-1.9 deg); the rope's EA halved, 5.59 / 6.49 deg; creep (read as drift: time in
the run) is the slow branch (400 s) 1.75 times as stiff, 0.37 / 0.45 deg (x1.5 0.25 / 0.30, x2
0.49 / 0.60; the others' creep 0.35-0.43 deg)."""

PRONYRING_MAX_STEP_S = 0.0
"""No finer stepping: unit 1's tip lies 0.059 deg RMS (0.39 max) from 0.25 ms steps at 20 ms,
0.012 (0.08) at 4 ms (unit 2 0.064 (0.52) / 0.012): the Prony branches are advanced implicitly
and the rope contacts in closed form."""


WORMEYELET_EFFECTS: dict[str, dict[str, float]] = {
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The wormeyelet plant's one effect keyword: a 120 deg sheath bend (added to every rope's lumen
wrap), 1.70 / 1.78 deg of tip (tip RMSE effect on minus off, units 1 / 2, noise-free, 120 s of
the experiment motion at 50 Hz; 60 deg 0.81 / 0.85), inside the others' 1.1-12.8 deg. Its laws
read the knob angle only at the tip (the silicone damper and the seal act on the knob: the same
samples played 8 times as fast move the tip 0.000 deg and the current 9.3 / 9.6 mA RMS; damper
x3 the current 10.1 / 10.8 mA, the tip 0.000) and nothing moves at a held knob (knob 1 held at
75 deg for 65 s, the other at 30: tip and current 0.000): rate and creep are not run. The worm
stage's play and its driving/back-driven loss, the eyelets' band that widens with the bend and
the disks on the cover are base physics; "none" is the nominal physics as written (docs/gap.md
"Session 27")."""

WORMEYELET_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"cross_wrap": 7.0},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Wormeyelet effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, units 1 / 2): the other plane's bend adding seven times the unit's share of wrap at
the eyelets (``cross_wrap``, the plant's constant that reads the other plane only), 1.59 / 1.44
deg (x3 0.48 / 0.41, x6 1.29 / 1.16, x8 1.90 / 1.72; the share removed altogether 0.22 / 0.19;
the others' coupling 1.5 deg); the stainless rope's EA halved, 4.51 / 4.23 deg."""

WORMEYELET_MAX_STEP_S = 0.0
"""No finer stepping: unit 1's tip lies 0.009 deg RMS (0.05 max) from 0.25 ms steps at 20 ms,
0.006 (0.05) at 4 ms (unit 2 0.013 / 0.011): every law is quasi-static in the knob angle."""


BELTBRAID_EFFECTS: dict[str, dict[str, float]] = {
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The beltbraid plant's one effect keyword: a 120 deg sheath bend (added to every rope's lumen
wrap), 5.00 / 4.16 deg of tip (tip RMSE effect on minus off, units 1 / 2, noise-free, 120 s of
the experiment motion at 50 Hz stepped at 2 ms; 60 deg 2.33 / 1.91), inside the others'
1.1-12.8 deg. Nothing at the tip reads the knob's speed or time: the knob's and the ropes' seals
are Coulomb laws smoothed over a few deg/s (saturated on every motion), the lumen's Bouc-Wen
microslip and the braid's relays are laws of travel, and the belt's Reynolds creep accumulates
with travel under load (the same samples played 8 times as fast, both at 0.25 ms steps, move
the tip 0.14 / 0.11 deg and the current 0.9 / 0.7 mA RMS, partly the step's lag; knob 1 held at
75 deg for 65 s, the other at 30: tip and current 0.000): rate and creep are not run. The
belt's creep and wind-up, the return springs, the seals, the microslip, the braid's own slip and
the notches' asymmetry are base physics; "none" is the nominal physics as written (docs/gap.md
"Session 28")."""

BELTBRAID_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"braid_slip_mm": 2.5},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Beltbraid effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, units 1 / 2, 2 ms steps): the braided shaft's crossings slipping 2.5 times as far
under the four ropes' load (``braid_slip_mm``, the plant's constant that couples the planes: the
shaft's shortening takes draw from every rope; the shaft is one part, knob 1's constant is
read), 1.54 / 1.52 deg (x2 1.05 / 1.04, x3 2.04 / 2.01, x4 2.99 / 2.85; the braid's slip and
elastic part removed altogether 1.56 / 1.42; the others' coupling 1.5 deg); the steel rope's EA
halved, 5.80 / 5.14 deg."""

BELTBRAID_MAX_STEP_S = 0.002
"""Stepped at 2 ms: the belt's wind-up, the lumen's capacity and the shaft's shortening lag one
step, and at the recording's 20 ms the linearised microslip overshoots (unit 2 with a 60 deg
bend: the tip at -159 deg against -68 at 4 ms). Against 0.25 ms steps the tip lies 0.30 / 0.29
deg RMS away at 10 ms, 0.19 / 0.18 at 4 ms, 0.14 / 0.11 at 2 ms (max 0.77 / 0.65), 0.09 / 0.06
at 1 ms (units 1 / 2, the experiment motion at 50 Hz)."""


RACKGREASE_EFFECTS: dict[str, dict[str, float]] = {
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The rackgrease plant's one effect keyword: a 120 deg shaft bend (added to every rope's lumen
wrap), 2.54 / 2.76 deg of tip (tip RMSE effect on minus off, units 1 / 2, noise-free, 120 s of
the experiment motion at 50 Hz stepped at 10 ms; 60 deg 1.18 / 1.28), inside the others'
1.1-12.8 deg. Creep is not run: knob 1 ramped to 75 deg and held 65 s (the other at 30), the
grease's flow settles the tip within the first second (0.44 / 0.39 deg) and it moves 0.000
after; no law reads time beyond the grease's viscosity (the rate case). The rack's cocking in
its guide and the eddy-current damper act on the current only (guide friction x3: tip 0.000,
current 24 / 21 mA; eddy peak x3: tip 0.000, 11 / 11 mA): base physics, as are the head's
gravity, the grease's yield and the ropes' slack; "none" is the nominal physics as written
(docs/gap.md "Session 28, round 2")."""

RACKGREASE_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"section_wrap_fraction": 7.0},
    "compliance": {"tendon_stiffness_N": 0.5},
    "rate": {"grease_viscosity_N_s_per_mm": 2.0, "section_viscosity_Nmm_s_per_rad": 2.0},
}
"""Rackgrease effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, units 1 / 2, 10 ms steps): the ropes wrapping seven times the unit's share of the
section's total bend (``section_wrap_fraction``, the plant's constant through which the other
plane's bend adds wrap; it reads the own plane's bend too), 1.46 / 1.65 deg (x2 0.24 / 0.27,
x4 0.72 / 0.81, x6 1.21 / 1.37; the share removed altogether 0.23 / 0.26; the head's gravity
removed 1.09 / 1.27; the others' coupling 1.5 deg); the rope's EA halved, 5.25 / 5.51 deg; the
grease twice as viscous (film on the ropes and packing of the section, one grease), 1.46 / 1.59
deg (x3 2.79 / 3.03; the section's alone x3 2.28 / 2.46, the film's alone x3 0.60 / 0.67; the
others' rate 1.1-1.9 deg; the same samples played 8 times as fast move the tip 7.3 / 7.8 deg)."""

RACKGREASE_MAX_STEP_S = 0.01
"""Stepped at 10 ms: every law is implicit in the step (the grease's return mapping over eta /
dt), stable at the recording's 20 ms, but first-order: against 0.25 ms steps the tip lies 0.11
/ 0.11 deg RMS away at 20 ms (max 0.57 / 0.67), 0.06 / 0.06 at 10 ms (max 0.30 / 0.30), 0.02 /
0.02 at 4 ms (units 1 / 2, the experiment motion at 50 Hz)."""
