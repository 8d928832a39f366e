"""Each family plant's self-test effects in its own physics: keywords and knob factors.

Sized before any diagnosis by the tip RMSE the effect moves (unit 1 or units 1-2, noise-free,
120 s of the experiment motion at 50 Hz, effect on minus off), so that every plant's case moves
its tip about as much as the others' do; a case a plant has no physics for has no entry here
and is not run (docs/gap.md, per plant's session). :mod:`tsmd.gap.presets` builds the presets.
"""

from __future__ import annotations

from typing import Any

LUMPED_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling": 1.0},
    "rate": {"viscous_N_s_per_m": 20.0},
    "compliance": {"tendon_compliance": 1.0},
    "curvature": {"sheath_curvature_deg": 120.0},
    "creep": {"creep_compliance_mm_per_N": 0.05},
}
"""The self-test effects in the lumped plant's own physics (its keywords), at strengths that move
the tip about as much as the capstan plant's do (2 x 120 s of the experiment motion, unit 1,
noise-free, effect on minus off, capstan / lumped): coupling 1.5 / 1.6 deg, rate 1.7 / 1.9 deg,
compliance 9.8 / 7.6 deg, curvature 12.0 / 8.5 deg, creep 0.35 / 0.42 deg (docs/gap.md)."""

SEGMENTS_BASE: dict[str, Any] = {"coupling": 0.0}
"""The segments plant couples its two planes by default; its "none" units and its simulator have
the coupling off, as the other plants' have every effect off."""

SEGMENTS_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling": 1.0},
    "rate": {"viscous_N_s_per_m": 90.0},
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The self-test effects in the segments plant's own physics, sized like the lumped ones (tip
RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion at 50 Hz; capstan
coupling 1.47, rate 1.70 deg): its nominal coupling 1.40 deg, lumen drag 90 N s/m (nominal 2)
1.72 deg, a 120 deg bend 6.91 deg. It has no creep: that case is not run on it."""

SEGMENTS_KNOB_EFFECTS: dict[str, dict[str, float]] = {"compliance": {"tendon_stiffness_N": 0.5}}
"""Compliance on segments: the unit's tendon EA halved (no keyword of its own; the other plants'
``tendon_compliance`` 1.0 is exactly that, docs/gap.md). Tip moved 6.42 deg (unit 1)."""


COILPIPE_BASE: dict[str, Any] = {"coupling_mm_per_rad2": 0.0}
"""The coilpipe plant shortens a tendon's path with the other plane's bend by default (0.25
mm/rad^2); its "none" units and its simulator have that off. What stays on is base physics: the
shaft's compression under all four tensions (a load coupling of both knobs), LuGre friction
with Stribeck and viscous terms (a rate dependence of its own) and the tip's relaxing stiffness
(2 s: a creep of its own); docs/gap.md "Session 11"."""

COILPIPE_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling_mm_per_rad2": 0.55},
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The self-test effects in the coilpipe plant's own keywords, sized like the others before any
diagnosis (tip RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion at
50 Hz): path coupling 0.55 mm/rad^2 1.51 deg, a 120 deg bend 5.14 deg."""

COILPIPE_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"viscous_N_s_per_mm": 8.0},
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"bend_creep_time_s": 2.0},
}
"""Coilpipe effects without a keyword, as factors on the unit's knob constants (same sizing):
lumen viscosity x8 1.56 deg, tendon EA halved 4.47 deg, the tip cover relaxing twice as slowly
(2 -> 4 s, its one creep branch) 0.58 deg."""


STICKSLIP_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The stickslip plant's one effect keyword: a 120 deg sheath bend moves its tip by 1.99 deg (tip
RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion at 50 Hz; the
other plants' 5-12 deg). Its knobs' coupling (each tendon rubs round the whole bent section) is
base physics with no constant of its own: that case is not run on it (as segments' creep)."""

STICKSLIP_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"creep_fast_share": 5.0},
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"creep_slow_share": 1.5},
}
"""Stickslip effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion): its only rate-dependent physics is the tendons' relaxation, so rate is the fast
(0.5 s) Maxwell branch five times as stiff, 1.11 deg (x3: 0.65; the protocol's 20 against 80
deg/s loops then differ by 0.36 / 0.16 deg RMS, the nominal unit's own 0.16 / 0.09); creep the
slow (12 s) branch 1.5 times as stiff, 0.38 deg (the other plants' creep 0.35-0.42 deg); the
tendon EA halved, 3.73 deg. "None" is the nominal physics as written: relaxing tendons,
stick-slip, the brake and the bend's coupling are its base (docs/gap.md "Session 12")."""


TWISTSHAFT_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The twistshaft plant's one effect keyword: a 120 deg sheath bend, 12.8 deg of tip (tip RMSE
effect on minus off, unit 1, noise-free, 120 s of the experiment motion at 50 Hz). The plant is
quasi-static with no load relaxation: no rate or creep physics, those cases are not run. Its
warm-up (24 -> 37 C in 60 s from every reset) is base physics: every recording, the data
sheet's included, starts at insertion (docs/gap.md "Session 13")."""

SCREWROD_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The screwrod plant's one effect keyword: a 120 deg sheath bend (adds to every tendon's wrap).
Its cross-coupling (both planes' bends add to each tendon's wrap) has no constant of its own and
it has no speed-dependent physics (Iwan contacts, a Norton creep in time): coupling and rate are
not run. Its tendons' creep is base physics as well (every recording, the reference units'
included, starts uncreeped at insertion): "none" is the nominal physics (docs/gap.md "Session
14")."""

SCREWROD_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"creep_time_s": 0.07},
}
"""Screwrod effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, the plant stepped at 4 ms): the braid's EA halved, 3.97 deg; its tendons creeping 14
times as fast (0.07 x the creep time: 17 s at 15 N, a braid not heat-set), 0.37 deg (the base
creep alone 0.03 deg; the other plants' creep 0.35-0.42 deg). The 120 deg bend: 1.41 deg."""

SCREWROD_MAX_STEP_S = 0.004
"""The screwrod plant holds its tip to 0.2 deg at steps up to 4 ms (its tests); at 20 ms its
walled knob's Newton step overshoots (torque spikes of hundreds of N m, tip 10 deg off)."""


NITINOL_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The nitinol plant's one effect keyword: a 120 deg sheath bend (adds to every lumen's wrap),
1.61 deg of tip (tip RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion
at 50 Hz). Its planes' coupling (one superelastic spine for both planes; the bend adds wrap) has
no constant of its own and nothing in it drifts in time: coupling and creep are not run. The
lubricant film's speed-dependent friction is base physics; "none" is the nominal physics
(docs/gap.md "Session 15")."""

NITINOL_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"film_damping_N_s_per_mm": 5.0},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Nitinol effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion): the lubricant film five times as viscous, 1.43 deg (x3 0.73, x8 2.48; the others'
rate 1.1-1.9 deg); the wire rope's EA halved, 8.27 deg. Its physics hold at 20 ms steps (tip
0.03 deg RMS from 4 ms ones, unit 1): no finer stepping."""


HELIXBELT_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The helixbelt plant's one effect keyword: a 120 deg sheath bend (added to the shaft's lay),
0.05 deg of tip (tip RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion
at 50 Hz; 0.22 deg at most): its tendons run in a helix, whose wrap and length barely change
with the shaft's curve. It is quasi-static with nothing that drifts in time and nothing speed-
dependent at the tip (the knob seal's friction saturates at 2 deg/s, on the motor only): rate
and creep are not run. "None" is the nominal physics as written (docs/gap.md "Session 15")."""

HELIXBELT_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"plane_error_deg": 2.2},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Helixbelt effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion): the helix's phase error at the tip (each plane bends out of its knob's plane, the
planes' cross-coupling) 2.2 times the unit's, 1.51 deg (x2 1.26, x2.5 1.89, x3 2.52; the others'
coupling 1.5 deg); the rope's EA halved, 2.03 deg. Its physics hold at 20 ms steps (tip 0.0005
deg RMS from 4 ms ones, unit 1): no finer stepping."""


RATESTATE_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The ratestate plant's one effect keyword: a 120 deg sheath bend (mid-shaft, adds to every
lumen contact's wrap), 1.94 deg of tip (tip RMSE effect on minus off, unit 1, noise-free, 120 s
of the experiment motion at 50 Hz). Its planes' coupling (both planes' bend adds wrap to every
tendon's distal contacts) has no constant of its own (``bend_lumen_friction`` rubs the own
plane's bend as well), and nothing moves at a held knob (contact ageing raises friction, it
moves no tendon): coupling and creep are not run. "None" is the nominal physics as written
(docs/gap.md "Session 16, round 2")."""

RATESTATE_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"ageing_b": 10.0},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Ratestate effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, the plant stepped at 4 ms): its only speed-dependent physics is the contacts'
rate-and-state friction, so rate is the state coefficient b ten times the unit's, 1.31 deg (x8
1.06, x11 1.59; the others' rate 1.1-1.9 deg; it makes the contacts stick-slip, whose events
move with the step: 0.9 deg RMS between 4 and 1 ms steps); the rope's EA halved, 3.74 deg."""

RATESTATE_MAX_STEP_S = 0.004
"""The nominal ratestate unit's tip lies within 0.08 deg (0.005 RMS) of 1 ms steps at 4 ms steps,
0.72 deg (0.05 RMS) at 20 ms (unit 1, 120 s of the experiment motion)."""


TWISTSHAFT_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"lumen_angle_error_deg": 4.5},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Twistshaft effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion): its lumens sit off their planes (1.5 deg) and the shaft's twist turns the planes, a
coupling of its base; the case puts the lumens 4.5 times as far off, 1.53 deg (the others'
coupling 1.5 deg); the tendon EA halved, 3.59 deg."""


WARMGEAR_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 60.0}}
"""The warmgear plant's one effect keyword: a 60 deg sheath bend (added to the shaft contact's
wrap), 2.10 deg of tip (tip RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment
motion at 50 Hz, 4 ms steps; unit 2 2.90). The others' 120 deg moves it 15.9 deg (20 ms steps:
90 deg 10.8, 75 deg 3.63): its lumped contact's friction x wrap reaches the plant's 0.95 cap
once the film is squeezed, outside the others' 1.1-12.8 deg (30 deg 0.79, 45 deg 1.34). Its
planes' coupling (the section's total bend, both planes, is the wrap of the tendons' distal
contact) has no constant of its own (``bend_wrap_share`` rubs the own plane's bend as well: 0.5
-> 1.0 moves the tip 0.64 deg), and nothing creeps under load: coupling and creep are not run.
The shaft's warm-up (slack shrinking, section softening after insertion) is base physics: every
recording, the reference units' included, starts at insertion; with three times the thermal
mismatch it moves the tip 1.29 deg over the motion but drifts 0.0 deg / 0.6 mA over a held
loaded dwell beyond an unloaded one (protocol, unit 1), below one sample's noise. "None" is
the nominal physics as written. Sized on the plant's re-tuned constants (s18-plant a6c2b95;
docs/gap.md "Session 18")."""

WARMGEAR_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"film_viscous_N_s_per_mm": 2.0},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Warmgear effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, 4 ms steps): its only speed-dependent physics is the sheath film's shear, so rate is
the film twice as viscous, 1.63 deg (unit 2 1.62; at 20 ms x1.5 0.81, x2.5 2.39, x3 3.14; the
others' rate 1.1-1.9 deg), whose protocol fast-minus-slow contrast is 0.69 deg / 1.6 mA (unit
1; detectable); the rope's EA halved, 3.44 deg (unit 2 3.09)."""

WARMGEAR_MAX_STEP_S = 0.004
"""The nominal warmgear unit's tip lies within 0.10 deg (0.015 RMS) of 1 ms steps at 4 ms
steps, 0.50 deg (0.088 RMS) at 20 ms (unit 1, 120 s of the experiment motion): as ratestate."""


ARCHWAVE_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The archwave plant's one effect keyword: a 120 deg sheath bend (added to the path's arch, in
its plane: wrap for every tendon, path slack by lumen), 4.47 / 3.58 deg of tip (tip RMSE effect
on minus off, units 1 / 2, noise-free, 120 s of the experiment motion at 50 Hz). Its planes'
coupling has no constant of its own (``section_wrap_share`` and ``bend_stiffening_per_rad2``
take the own plane's bend as well: x2 / x3 move the tip 0.22 / 0.64 deg); nothing at the tip
depends on speed (the wave generator's viscous and Coulomb drags, saturated at 2 deg/s, are on
the motor: x10 viscous moves the tip 0.000 deg, the current 15 mA RMS) or drifts at a held knob
(Bouc-Wen is rate-independent; the warming torque constant moves the current only): coupling,
rate and creep are not run. "None" is the nominal physics as written (docs/gap.md "Session
20")."""

ARCHWAVE_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "compliance": {"tendon_stiffness_N": 0.5, "coil_compliance_mm_per_N": 2.0},
}
"""Compliance on archwave as factors on the unit's knob constants, sized before any diagnosis
(same criterion): the tendon's whole compliance doubled, the rope's EA halved and its coil
sheath's shortening per newton doubled (the coil is 60 % of it: the EA halved alone 1.30 / 1.46
deg, below every other plant's 2.0-9.8), 2.89 / 2.91 deg (units 1 / 2)."""

ARCHWAVE_MAX_STEP_S = 0.004
"""The archwave unit's tip lies 0.052 deg RMS (0.66 max) from 0.5 ms steps at 20 ms steps,
0.028 (0.34) at 4 ms (unit 1; unit 2 0.051 / 0.028): the gear's one-step lag, as ratestate."""


JAWCRIMP_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The jawcrimp plant's one effect keyword: a 120 deg sheath bend (added to both lumens' wrap
at the friction node), 5.12 / 3.63 deg of tip (tip RMSE effect on minus off, units 1 / 2,
noise-free, 120 s of the experiment motion at 50 Hz, 4 ms steps; 60 deg 2.14 / 1.57), inside the
others' 1.1-12.8 deg. Its planes' coupling has no constant of its own: the shaft shortens under
all four ropes' load (``shaft_gap_mm`` x2 moves the tip 2.8 deg, but the own knob's load closes
the same gaps) and the section stiffens with the total bend (``bend_stiffening_per_rad2`` x3
0.11 / 0.09 deg, the own plane's bend as well); nothing at the tip depends on speed (the knob
seal, saturated at 2 deg/s, and the drum's inertia act on the motor: the seal x3 moves the tip
0.000 deg, the current 11 mA RMS): coupling and rate are not run. The heart's push is base
physics; "none" is the nominal physics as written, the crimps' own creep included (docs/gap.md
"Session 21")."""

JAWCRIMP_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"crimp_creep_mm_per_s": 30.0},
}
"""Jawcrimp effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, 4 ms steps, units 1 / 2): the steel rope's EA halved, 3.88 / 3.35 deg (the shaft's
solid stiffness halved as well 4.45 / 3.74: the rope is most of the tendon's compliance, the
coil gaps close within 3 N); the pull-ring crimps creeping 30 times as fast (a crimp swaged
loose), 0.43 / 0.37 deg (x10 0.20 / 0.18, the nominal creep alone 0.04 / 0.03; the others'
creep 0.35-0.42 deg), drifting 0.13 / 0.12 deg and 1.9 mA over the protocol's held loaded
dwell beyond an unloaded one."""

JAWCRIMP_MAX_STEP_S = 0.004
"""The nominal-scatter unit's tip lies 0.045 deg RMS (0.61 max) from 1 ms steps at 20 ms steps,
0.008 (0.17) at 4 ms (unit 1, 120 s of the experiment motion): the crimps' creep and the node's
stick are integrated per step; as data it is stepped at 4 ms, the plant's own step."""
