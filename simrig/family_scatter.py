"""Unit-to-unit scatter of every built-in plant's constants (used by :mod:`simrig.family`).

Relative half-range of a uniform draw around the nominal value, per plant and constant, with
why it scatters that much; a plant's table lists only the constants a unit draws (the others
are the product's design).
"""

from __future__ import annotations

SCATTER: dict[str, dict[str, float]] = {
    "capstan": {
        "pulley_radius_mm": 0.02,  # machined part
        "slack_pos_mm": 0.15,  # assembly: tendon cut and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
        "tendon_stiffness_N": 0.15,  # tendon lot (EA)
        "sheath_length_m": 0.02,
        "free_length_m": 0.20,
        "sheath_friction": 0.15,  # coating, lubricant
        "sheath_wrap_deg": 0.10,  # coil pitch
        "routing_wrap_deg": 0.10,
        "routing_friction": 0.15,
        "sheath_drag_N": 0.20,
        "bend_stiffness_Nm_per_rad": 0.15,  # polymer cover, links
        "bend_friction_Nm": 0.20,
        "handle_friction_Nm": 0.20,  # knob bearing / brake setting
        "handle_stiction_Nm": 0.20,
        "handle_slip_deg": 0.20,
    },
    "lumped": {
        "pulley_radius_mm": 0.02,
        "slack_pos_mm": 0.15,
        "slack_neg_mm": 0.15,
        "toe_mm": 0.20,
        "tendon_stiffness_N": 0.15,
        "sheath_length_m": 0.02,
        "free_length_m": 0.20,
        "guide_wrap_deg": 0.10,
        "guide_friction": 0.15,
        "sheath_wrap_deg": 0.10,
        "sheath_friction": 0.15,
        "sheath_drag_N": 0.20,
        "presliding_mm": 0.20,
        "tendon_offset_mm": 0.05,
        "bend_stiffness_Nm_per_rad": 0.15,
        "bend_friction_Nm": 0.20,
        "bend_presliding_deg": 0.20,
        "handle_friction_Nm": 0.20,
        "handle_presliding_deg": 0.20,
    },
    "segments": {
        "pulley_radius_mm": 0.02,  # machined part
        "slack_pos_mm": 0.15,  # tendon cut and crimped by hand
        "slack_neg_mm": 0.15,
        "toe_mm": 0.20,  # crimp geometry
        "tendon_stiffness_N": 0.15,  # tendon lot (EA)
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "sheath_friction": 0.15,  # liner coating, lubricant
        "sheath_wrap_deg": 0.10,  # lumen helix pitch
        "sheath_drag_N": 0.20,  # lumen preload
        "presliding_mm": 0.20,  # contact micro-geometry
        "stick_fraction": 0.10,
        "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
        "bend_stiffness_Nm_per_rad": 0.15,  # polymer cover, links
        "bend_stiffening_per_rad2": 0.20,
        "bend_hysteresis_Nm": 0.20,  # link rubbing
        "bend_yield_deg": 0.20,
        "handle_friction_Nm": 0.20,  # knob bearing / brake setting
        "handle_presliding_deg": 0.20,
    },
    "coilpipe": {
        "pulley_radius_mm": 0.02,  # machined drum
        "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
        "slack_pos_mm": 0.15,  # tendon cut and crimped by hand
        "slack_neg_mm": 0.15,
        "toe_mm": 0.20,  # crimp and strand lay
        "tendon_stiffness_N": 0.15,  # cable lot (EA)
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "sheath_friction": 0.15,  # liner coating, lubricant
        "sheath_wrap_deg": 0.10,  # lumen helix pitch
        "sheath_drag_N": 0.25,  # liner preload on the cable
        "stribeck_ratio": 0.05,  # static/kinetic ratio of the liner (1.24-1.37 at 1.3)
        "stribeck_speed_mm_s": 0.30,  # lubricant film: the least known of the friction constants
        "viscous_N_s_per_mm": 0.30,  # lubricant amount and viscosity
        "presliding_mm": 0.20,  # contact micro-geometry
        "bend_stiffness_Nm_per_rad": 0.15,  # tip cover and links
        "bend_creep_stiffness_Nm_per_rad": 0.25,  # polymer batch, moulding
        "bend_creep_time_s": 0.30,
        "handle_friction_Nm": 0.20,  # knob bearing / detent setting
        "handle_presliding_deg": 0.20,
        "gear_backlash_deg": 0.30,  # adapter tooth play (tolerance stack of two parts)
        "gear_stiffness_Nm_per_deg": 0.20,  # adapter material and fit
    },
    "stickslip": {
        "pulley_radius_mm": 0.02,  # machined drum
        "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
        "slack_pos_mm": 0.15,  # tendon cut and crimped by hand
        "slack_neg_mm": 0.15,
        "toe_mm": 0.20,  # crimp and braid lay
        "tendon_stiffness_N": 0.15,  # braid lot (EA)
        "creep_fast_share": 0.20,  # polymer lot and braid tension: relaxation scatters widely
        "creep_fast_time_s": 0.30,
        "creep_slow_share": 0.20,
        "creep_slow_time_s": 0.30,
        "free_length_pos_m": 0.20,  # handle assembly
        "free_length_neg_m": 0.20,
        "sheath_length_m": 0.02,  # cut to length
        "sheath_wrap_deg": 0.10,  # lumen helix pitch
        "sheath_friction": 0.15,  # liner coating, lubricant
        "stiction_ratio": 0.05,  # one material pair
        "sheath_drag_N": 0.20,  # liner preload
        "bend_stiffness_Nm_per_rad": 0.15,  # tip cover and links
        "bend_stiffening_per_rad2": 0.20,  # cover strain-hardening, polymer batch
        "tip_mass_g": 0.10,  # transducer head and links
        "tip_length_mm": 0.03,  # moulded links
        "drive_stiffness_Nm_per_rad": 0.20,  # cable tension set at assembly, coupling fit
        "handle_friction_Nm": 0.25,  # knob brake as left by the last user: the least controlled
        "brake_stiction_ratio": 0.05,  # one pad material
    },
    "twistshaft": {
        "pulley_radius_mm": 0.02,  # machined drum
        "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
        "lumen_angle_error_deg": 0.50,  # angular tolerance of the extrusion die (1-3 deg)
        "lumen_helix_deg": 0.30,  # extrusion twist: the least controlled geometry
        "slack_pos_mm": 0.15,  # tendon cut and crimped by hand
        "slack_neg_mm": 0.15,
        "toe_mm": 0.20,  # braid lay and crimp
        "tendon_stiffness_N": 0.15,  # braid lot (EA)
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "bend_length_mm": 0.05,  # moulded links
        "sheath_wrap_deg": 0.10,  # lumen path in the shaft
        "sheath_friction": 0.15,  # liner coating, lubricant
        "friction_exponent": 0.05,  # one material pair (0.67-0.9 over materials)
        "contact_load_N": 0.25,  # surface roughness of the liner
        "sheath_drag_N": 0.20,  # lumen preload
        "bend_stiffness_Nm_per_rad": 0.15,  # tip cover and links
        "handle_friction_Nm": 0.20,  # knob bearing / O-ring
        "handle_presliding_deg": 0.20,
    },
    "screwrod": {
        "screw_lead_mm": 0.01,  # moulded collar thread
        "screw_radius_mm": 0.01,
        "thread_friction": 0.15,  # dry polymer thread, grease left from assembly
        "handle_friction_Nm": 0.20,  # O-ring squeeze
        "handle_presliding_deg": 0.20,  # thread flank fit
        "slack_pos_mm": 0.15,  # tendon cut and knotted to its nut by hand
        "slack_neg_mm": 0.15,
        "toe_mm": 0.20,  # braid lay
        "tendon_stiffness_N": 0.15,  # braid lot (EA)
        "creep_limit_mm": 0.30,  # UHMWPE creep: lot and braid heat-setting scatter widely
        "creep_time_s": 0.30,
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "sheath_wrap_deg": 0.10,  # lumen path in the shaft
        "sheath_friction": 0.15,  # liner coating, lubricant
        "sheath_drag_N": 0.20,  # lumen preload
        "presliding_mm": 0.20,  # liner and braid compliance
        "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
        "bend_length_mm": 0.03,  # moulded links
        "bend_stiffness_Nm_per_rad": 0.15,  # tip cover and braid
    },
    "nitinol": {
        "pulley_radius_mm": 0.02,  # machined drum
        "slack_pos_mm": 0.15,  # tendon cut and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # wire-rope lot (EA: steel scatters less than polymer)
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "sheath_wrap_deg": 0.10,  # lumen path in the shaft
        "sheath_friction": 0.15,  # liner and how much lubricant assembly left
        "sheath_drag_N": 0.20,  # lumen ovality
        "film_damping_N_s_per_mm": 0.30,  # lubricant amount and viscosity: the least controlled
        "tendon_offset_mm": 0.05,  # lumen placement in the moulding
        "offset_ratio_neg": 0.03,  # the second lumen against the first (one mould)
        "bend_length_mm": 0.03,  # laser-cut spine length
        "cover_stiffness_Nm_per_rad": 0.15,  # silicone cover and braid
        "handle_friction_Nm": 0.20,  # knob O-ring squeeze
        "handle_presliding_deg": 0.20,
        "backbone_od_mm": 0.003,  # drawn NiTi tube: +-0.01 mm on 2 mm (the tube is one part:
        "backbone_id_mm": 0.003,  # the plant takes the mean of the two knobs' draws)
        "slot_stiffness_factor": 0.10,  # laser kerf width
        "austenite_modulus_GPa": 0.10,  # heat treatment of the lot
        "upper_plateau_MPa": 0.06,  # Af of the lot (+-3 K at 6.5 MPa/K) and processing
        "lower_plateau_MPa": 0.10,  # the lower plateau scatters more than the upper
        "transformation_strain": 0.10,
        "plateau_hardening": 0.20,  # cut pattern and texture
    },
    "helixbelt": {
        "pulley_radius_mm": 0.02,  # moulded belt pulley and drum
        "belt_clearance_deg": 0.30,  # tooth vs groove: moulding tolerance of two parts
        "belt_ref_deflection_deg": 0.20,  # belt lot (cord and tooth rubber) and its tension
        "slack_pos_mm": 0.15,  # tendon wound and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # wire-rope lot (steel: less than polymer)
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "helix_pitch_mm": 0.10,  # lumen twist of the extrusion (set by haul-off vs rotation)
        "helix_radius_mm": 0.03,  # lumen placement in the extrusion
        "sheath_wrap_deg": 0.10,  # the shaft's lay
        "sheath_friction": 0.15,  # liner and rope surface
        "sheath_drag_N": 0.20,  # lumen ovality
        "tendon_offset_mm": 0.05,  # lumen placement in the bending section
        "bend_length_mm": 0.03,  # braided section cut to length
        "bend_stiffness_Nm_per_rad": 0.15,  # braid angle and cover durometer
        "braid_stiffening_per_rad2": 0.20,
        "braid_friction_Nm": 0.25,  # inter-wire friction: braid tension and lubricity
        "braid_slip_deg": 0.20,
        "plane_error_deg": 0.50,  # helix phase at the section: extrusion twist over 1 m
        "handle_friction_Nm": 0.20,  # knob shaft seal squeeze
    },
    "ratestate": {
        "pulley_radius_mm": 0.02,  # machined drum
        "slack_pos_mm": 0.15,  # tendon wound and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # wire-rope lot (steel: less than polymer)
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "bend_length_mm": 0.03,  # link stack cut to length
        "sheath_wrap_deg": 0.15,  # lumen waviness of the extrusion and the shaft's lay
        "curve_position": 0.10,  # where the shaft's set curve lies (coiled in its box)
        "curve_share": 0.20,
        "sheath_friction": 0.15,  # liner and rope surface, lubricant left from assembly
        "ageing_b": 0.30,  # polymer contact ageing: liner lot, the least known constant
        "ageing_dc_mm": 0.30,  # contact asperity size
        "sheath_drag_N": 0.25,  # lumen ovality
        "presliding_mm": 0.20,  # liner shear compliance
        "tendon_offset_mm": 0.05,  # lumen placement in the links
        "bend_stiffness_Nm_per_rad": 0.15,  # cover durometer and links
        "bend_lumen_friction": 0.20,  # coil lumen in the links
        "link_friction": 0.25,  # link pivots: moulding and grease
        "link_drag_Nm": 0.25,  # cover's internal friction
        "handle_friction_Nm": 0.20,  # knob bearing and seal
    },
    "warmgear": {
        "gear_play_deg": 0.30,  # moulded gears: tolerance stack of two parts and a centre distance
        "mesh_stiffness_Nmm_per_deg": 0.20,  # POM lot, moisture, face width
        "mesh_friction": 0.20,  # flank finish, grease left from assembly
        "drum_friction_Nmm": 0.25,  # bushing fit and seal squeeze
        "pulley_radius_mm": 0.02,  # moulded drum
        "slack_pos_mm": 0.15,  # tendon wound and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # wire-rope lot (steel)
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "inserted_share": 0.15,  # how deep the probe sits (the patient)
        "thermal_mismatch_per_K": 0.20,  # shaft braid angle and Pebax lot
        "sheath_wrap_deg": 0.10,  # the shaft's lay
        "sheath_friction": 0.15,  # liner surface
        "film_friction": 0.20,  # flush fluid and coating hydration
        "sheath_drag_N": 0.20,  # lumen ovality
        "film_viscous_N_s_per_mm": 0.30,  # film amount: the least known constant
        "squeeze_time_s": 0.30,  # lumen clearance (thickness cubed)
        "entrain_length_mm": 0.25,
        "tendon_offset_mm": 0.05,  # lumen placement in the section
        "bend_stiffness_Nm_per_rad": 0.15,  # cover durometer and spine cut
        "section_softening_per_K": 0.20,  # Pebax lot
        "handle_friction_Nm": 0.20,  # knob O-ring squeeze
    },
    "archwave": {
        "torque_constant_ratio": 0.08,  # motor lot: magnet and winding (+-8 % on the sheet)
        "standby_power_W": 0.20,  # drive electronics and hold current
        "thermal_resistance_K_per_W": 0.15,  # how the motor sits in the sealed handle
        "cogging_mNm": 0.30,  # magnet segment placement
        "flex_stiffness_Nm_per_rad": 0.20,  # moulded polymer flexspline: lot and wall thickness
        "flex_stiffening_Nm_per_rad3": 0.25,
        "flex_hysteresis_deg": 0.30,  # tooth-flank fit
        "kinematic_error_deg": 0.40,  # wave generator ellipse and tooth profile tolerance
        "kinematic_phase_deg": 1.0,  # where the error peaks: assembly (any phase)
        "wave_drag_Nm": 0.25,  # bearing preload, grease
        "pulley_radius_mm": 0.02,  # moulded drum
        "handle_friction_Nm": 0.20,  # knob shaft seal squeeze
        "tensioner_preload_N": 0.20,  # spring lot and idler position
        "tensioner_rate_N_per_mm": 0.15,  # spring lot
        "slack_pos_mm": 0.15,  # tendon wound and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # wire-rope lot (steel)
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "coil_compliance_mm_per_N": 0.25,  # coil pitch and how it was pre-compressed
        "sheath_friction": 0.15,  # coil and rope surface, lubricant
        "sheath_wrap_deg": 0.10,  # the shaft's lay
        "sheath_drag_N": 0.20,  # coil ovality
        "coil_clearance_mm": 0.20,  # coil inner diameter vs rope
        "lumen_offset_mm": 0.30,  # where the coil bundle sits in the shaft
        "tendon_offset_mm": 0.05,  # lumen placement in the section
        "bend_stiffness_Nm_per_rad": 0.15,  # cover durometer and spine cut
        "bend_stiffening_per_rad2": 0.20,
    },
    "jawcrimp": {
        "pulley_radius_mm": 0.02,  # moulded drum
        "jaw_play_deg": 0.40,  # spider set and hub bore fit
        "jaw_twist_deg": 0.20,  # spider durometer lot
        "jaw_torque_Nm": 0.20,
        "slack_pos_mm": 0.15,  # rope cut and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # wire-rope lot (steel)
        "free_length_m": 0.20,  # handle assembly, idler positions
        "sheath_length_m": 0.02,  # cut to length
        "node_share": 0.15,  # where the lumen's friction concentrates
        "sheath_friction": 0.15,  # liner and rope surface, lubricant
        "sheath_wrap_deg": 0.10,  # the shaft's lay in the patient
        "sheath_drag_N": 0.20,  # lumen seal, idler bushing preload
        "idler_friction": 0.25,  # bushing fit and grease
        "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
        "bend_stiffness_Nmm_per_rad": 0.15,  # cover polymer lot
        "shaft_gap_mm": 0.25,  # coil pitch and how it was pre-compressed
        "shaft_gap_load_N": 0.20,
        "shaft_stiffness_N_per_mm": 0.15,
        "crimp_creep_mm_per_s": 0.40,  # swage pressure
        "handle_friction_Nm": 0.20,  # knob shaft seal squeeze
        "heart_moment_Nmm": 0.30,  # where the probe lies against the heart
    },
    "cyclopebax": {
        "lost_motion_deg": 0.40,  # pin-roller clearance: moulded discs, tolerance stack
        "mesh_twist_deg": 0.20,  # pin and disc material lot, preload
        "mesh_friction": 0.25,  # grease left from assembly, pin finish
        "drum_radius_mm": 0.02,  # moulded drum
        "drum_friction_Nmm": 0.30,  # drum bushing fit
        "handle_friction_Nm": 0.40,  # the friction lock as the last operator left it
        "slack_pos_mm": 0.15,  # rope wound and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # wire-rope lot (steel)
        "free_length_m": 0.20,  # adapter and handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "sheath_wrap_deg": 0.10,  # the shaft's path in the patient
        "sheath_friction": 0.15,  # coil liner and rope surface, lubricant
        "lay_asymmetry": 0.30,  # how the rope's lay meets the coil's winding
        "sheath_drag_N": 0.20,  # lumen seal, coil ovality
        "tendon_offset_mm": 0.05,  # lumen placement in the section
        "bend_stiffness_Nmm_per_rad": 0.15,  # Pebax lots of the three zones, reflow
        "yield_tension_N": 0.15,  # crimp swage pressure, rope lot
        "set_hardening_N_per_mm": 0.20,
    },
    "snakedent": {
        "drum_radius_mm": 0.02,  # moulded drum
        "slack_pos_mm": 0.15,  # rope wound and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # steel rope lot
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "sheath_wrap_deg": 0.10,  # the shaft's path in the patient
        "sheath_friction": 0.15,  # liner coating, lubricant
        "sheath_drag_N": 0.20,  # lumen seal, coil ovality
        "tendon_offset_mm": 0.04,  # rope holes drilled in each vertebra
        "roll_radius_mm": 0.03,  # ground rolling faces
        "hole_depth_mm": 0.06,  # hole exit below the face (deburring)
        "bend_stiffness_Nmm_per_rad": 0.15,  # spine spring and jacket lots
        "joint_friction_mm": 0.30,  # pin guides' finish, grease
        "joint_preload_N": 0.25,  # spine spring preload at assembly
        "handle_friction_Nm": 0.25,  # knob seal
        "detent_torque_Nm": 0.25,  # detent spring lot, ball seat wear
    },
    "planetwist": {
        "drum_radius_mm": 0.02,  # moulded drum on the carrier
        "carrier_play_deg": 0.30,  # tooth thickness and centre-distance tolerance of the stage
        "mesh_stiffness_Nmm_per_rad": 0.15,  # gear material lot (glass-filled POM)
        "planet2_error_deg": 0.50,  # planet pin positions drilled in the carrier
        "planet3_error_deg": 0.50,
        "carrier_stiffness_Nmm_per_rad": 0.15,
        "drum_bearing_Nmm": 0.30,  # bearing fit and grease
        "gear_efficiency": 0.02,  # grease, mesh finish
        "slack_pos_mm": 0.15,  # strand cut and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # strand lot
        "twist_coupling_mm": 0.10,  # lay length of the strand lot
        "twist_share": 0.10,
        "swivel_friction_Nmm": 0.30,  # swivel crimp's seat finish
        "swivel_arm_mm": 0.20,
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "sheath_wrap_deg": 0.10,  # the shaft's path in the patient
        "sheath_friction": 0.15,  # liner coating, lubricant
        "sheath_drag_N": 0.20,  # lumen seal
        "tendon_offset_mm": 0.04,  # lumen placement in the extrusion
        "bend_stiffness_Nmm_per_rad": 0.15,  # jacket and coil lots
        "bend_stiffening_per_rad2": 0.20,
        "handle_friction_Nm": 0.25,  # knob seal
        "flow_moment_Nmm": 0.40,  # where in the chamber the tip sits (not the catheter's part)
    },
    "notchclutch": {
        "drum_radius_mm": 0.02,  # moulded drum
        "clutch_capacity_Nmm": 0.15,  # wave-spring preload and facing friction of the clutch
        "clutch_kinetic_ratio": 0.05,
        "handle_friction_Nm": 0.20,  # knob seal
        "slack_pos_mm": 0.15,  # braid cut and knotted by hand
        "slack_neg_mm": 0.15,
        "toe_mm": 0.20,  # braid crimp of the lot
        "tendon_stiffness_N": 0.10,  # aramid lot
        "rate_stiffening": 0.20,
        "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
        "sheath_friction": 0.15,  # coating thickness and cure
        "dry_friction_ratio": 0.10,
        "soak_time_s": 0.30,  # coating thickness
        "stribeck_rise": 0.20,
        "sheath_wrap_deg": 0.10,  # routing in the handle
        "sheath_drag_N": 0.20,  # lumen fit
        "bend_stiffness_Nmm_per_rad": 0.15,  # laser cut, cover durometer
        "notch_close_deg": 0.05,  # notch width of the cut
        "tissue_friction_Nmm": 0.25,  # the patient's mucosa, the probe's position
        "tissue_friction_ratio": 0.25,
    },
    "pronyring": {
        "drum_radius_mm": 0.02,  # moulded drum
        "handle_friction_Nm": 0.20,  # knob seal
        "slack_pos_mm": 0.15,  # rope cut and crimped by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # rope lot (EA)
        "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
        "shaft_offset_mm": 0.10,
        "sheath_friction": 0.15,  # liner lot, lubricant
        "friction_load_exponent": 0.20,
        "sheath_wrap_deg": 0.10,  # routing in the handle, the patient's path
        "sheath_drag_N": 0.20,  # lumen fit
        "bend_stiffness_Nmm_per_rad": 0.12,  # Pebax lot, wall thickness
        "prony_fast_Nmm_per_rad": 0.20,  # relaxation spectrum of the lot
        "prony_fast_s": 0.25,
        "prony_mid_Nmm_per_rad": 0.20,
        "prony_slow_Nmm_per_rad": 0.25,
        "ring_tilt_Nmm_per_rad": 0.25,  # bond line thickness
        "ring_axial_N_per_mm": 0.20,
        "ring_clocking_deg": 0.50,  # anchor clocking: assembly tolerance
        "breathing_wrap_deg": 0.40,  # the patient
    },
    "wormeyelet": {
        "worm_lead_deg": 0.03,  # ground worm thread
        "worm_friction": 0.25,  # grease left from assembly, wheel moulding
        "worm_play_deg": 0.30,  # wheel tooth thickness and centre distance: a tolerance stack
        "drum_radius_mm": 0.02,  # moulded drum
        "slack_pos_mm": 0.15,  # rope crimped to the drum by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # rope lot (EA)
        "contact_fraction": 0.10,  # where the shaft's sag puts the rope on the liner
        "sheath_friction": 0.15,  # liner batch, lubricant
        "sheath_wrap_deg": 0.10,  # lumen helix pitch
        "sheath_drag_N": 0.25,  # liner preload
        "tendon_offset_mm": 0.05,  # eyelet placement in the disks
        "section_stiffness_Nmm_per_rad": 0.15,  # backbone spring and cover
        "eyelet_friction": 0.20,  # eyelet finish (deburred by hand)
        "disk_friction_N": 0.25,  # disk fit in the sleeve
        "cross_wrap": 0.20,
        "handle_friction_Nm": 0.20,  # worm shaft seal squeeze
        "damper_Nm_s_per_rad": 0.20,  # oil fill and gap of the damper
        "damper_thinning_rad_s": 0.20,
    },
    "beltbraid": {
        "return_preload_Nm": 0.25,  # spring lot and how far each is wound at assembly
        "return_rate_Nm_per_rad": 0.20,
        "handle_friction_Nm": 0.20,  # knob seal squeeze
        "belt_stiffness_Nm_per_rad": 0.20,  # belt lot (polyurethane cord) and its tension
        "belt_creep_per_Nm": 0.30,  # belt tension at assembly: the least known constant
        "drum_radius_mm": 0.02,  # moulded pulley and drum
        "slack_pos_mm": 0.15,  # rope crimped to the drum by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # rope lot (EA)
        "free_length_m": 0.20,  # handle assembly
        "sheath_length_m": 0.02,  # cut to length
        "contact_fraction": 0.10,  # where the shaft's lay concentrates the friction
        "sheath_friction": 0.15,  # liner lot, lubricant
        "sheath_wrap_deg": 0.10,  # routing in the handle, the shaft's lay
        "sheath_drag_N": 0.25,  # rope straightness, lumen fit
        "microslip_floor_mm": 0.30,  # liner compliance
        "braid_slip_mm": 0.30,  # braid angle and pick count of the shaft lot
        "braid_compliance_mm_per_N": 0.15,
        "braid_onset_N": 0.25,  # braid tension at extrusion
        "braid_hold_N": 0.25,
        "tendon_offset_mm": 0.04,  # lumen placement in the section
        "bend_stiffness_Nmm_per_rad": 0.12,  # laser cut (kerf width) and cover durometer
        "notch_asymmetry": 0.05,  # notch depth tolerance
    },
    "rackgrease": {
        "pinion_radius_mm": 0.02,  # moulded pinion
        "rack_offset_mm": 0.10,  # where the rope anchors are crimped on the rack
        "guide_friction": 0.20,  # acetal rack on its brass guide, assembly grease
        "handle_friction_Nm": 0.25,  # wave-spring preload of the guide
        "eddy_peak_Nm": 0.15,  # magnet strength and air gap of the eddy disc
        "slack_pos_mm": 0.15,  # rope crimped to the rack by hand
        "slack_neg_mm": 0.15,
        "tendon_stiffness_N": 0.10,  # rope lot (EA)
        "free_length_m": 0.15,  # handle routing
        "sheath_length_m": 0.02,  # cut to length
        "contact_fraction": 0.10,  # where the shaft's lay concentrates the friction
        "sheath_friction": 0.15,  # liner lot, lubricant
        "sheath_wrap_deg": 0.10,  # routing in the handle, the shaft's lay
        "sheath_drag_N": 0.25,  # rope straightness, lumen fit
        "section_yield_Nmm": 0.25,  # grease fill of the section (amount, batch consistency)
        "section_gel_Nmm_per_rad": 0.25,
        "section_viscosity_Nmm_s_per_rad": 0.25,
        "tendon_offset_mm": 0.04,  # lumen placement in the section
        "bend_stiffness_Nmm_per_rad": 0.12,  # spine cut and cover durometer
        "head_moment_Nmm": 0.10,  # transducer head mass and where it sits
    },
}
