//! The plant in the environment inputs (environment_inputs = 1): the disturbance budget against closed
//! forms written here independently of `math::surface_forces` (a box whose faces are worked out by hand),
//! the gravity gradient from the input position against the circular orbit's, the residual dipole, and the
//! refusal of unconnected inputs.

use nalgebra::{Matrix3, Vector3};

use super::{plant, P};
use crate::math::environment::CircularOrbit;
use crate::models::attitude::plant::AttitudePlantVars;

/// A 6U-like box 0.1 × 0.2 × 0.3 m (x, y, z) with its centre of mass offset by (0.01, −0.02, 0.03) m from the
/// geometric centre: six facets at the face centres, the ±z faces specular 0.3/diffuse 0.2, the others black.
fn six_u(v: &mut AttitudePlantVars) {
    let (a, b, c) = (0.1, 0.2, 0.3);
    let off = Vector3::new(0.01, -0.02, 0.03);
    let faces = [
        (b * c, Vector3::x(), Vector3::new(a / 2.0, 0.0, 0.0), 0.0, 0.0),
        (b * c, -Vector3::x(), Vector3::new(-a / 2.0, 0.0, 0.0), 0.0, 0.0),
        (a * c, Vector3::y(), Vector3::new(0.0, b / 2.0, 0.0), 0.0, 0.0),
        (a * c, -Vector3::y(), Vector3::new(0.0, -b / 2.0, 0.0), 0.0, 0.0),
        (a * b, Vector3::z(), Vector3::new(0.0, 0.0, c / 2.0), 0.3, 0.2),
        (a * b, -Vector3::z(), Vector3::new(0.0, 0.0, -c / 2.0), 0.3, 0.2),
    ];
    let set = |area: &mut f64, n: &mut Vector3<f64>, ctr: &mut Vector3<f64>, cs: &mut f64, cd: &mut f64, k: usize| {
        (*area, *n, *ctr, *cs, *cd) = (faces[k].0, faces[k].1, faces[k].2 - off, faces[k].3, faces[k].4);
    };
    set(&mut v.facet1_area, &mut v.facet1_normal, &mut v.facet1_centre, &mut v.facet1_specular, &mut v.facet1_diffuse, 0);
    set(&mut v.facet2_area, &mut v.facet2_normal, &mut v.facet2_centre, &mut v.facet2_specular, &mut v.facet2_diffuse, 1);
    set(&mut v.facet3_area, &mut v.facet3_normal, &mut v.facet3_centre, &mut v.facet3_specular, &mut v.facet3_diffuse, 2);
    set(&mut v.facet4_area, &mut v.facet4_normal, &mut v.facet4_centre, &mut v.facet4_specular, &mut v.facet4_diffuse, 3);
    set(&mut v.facet5_area, &mut v.facet5_normal, &mut v.facet5_centre, &mut v.facet5_specular, &mut v.facet5_diffuse, 4);
    set(&mut v.facet6_area, &mut v.facet6_normal, &mut v.facet6_centre, &mut v.facet6_specular, &mut v.facet6_diffuse, 5);
    (v.inertia.x, v.inertia.y, v.inertia.z) = (0.1, 0.08, 0.05);
    v.environment_inputs = 1;
    v.r = Vector3::new(6_878_137.0, 0.0, 0.0);
    v.v = Vector3::new(0.0, 5383.0, 5383.0);
    v.b_eci = Vector3::new(1e-5, 0.0, 3e-5);
    v.sun_eci = Vector3::x();
}

fn rel_err(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    (a - b).norm() / b.norm().max(1e-300)
}

#[test]
fn drag_on_a_box_along_x_is_the_front_face_alone() {
    // identity attitude, relative velocity along +x body: only the +x face meets the flow
    let mut p: P = plant(|v| {
        six_u(v);
        v.earth_rotation_rate = 0.0;
        v.v = Vector3::new(7600.0, 0.0, 0.0);
        v.rho = 3e-12;
    });
    p.outputs(0.0).unwrap();
    let f = -0.5 * 3e-12 * 7600.0f64.powi(2) * 2.2 * (0.2 * 0.3);
    let force = Vector3::new(f, 0.0, 0.0);
    let centre = Vector3::new(0.05 - 0.01, 0.02, -0.03);
    assert!(rel_err(&p.v.force_aero, &force) < 1e-14, "{:?}", p.v.force_aero);
    assert!(rel_err(&p.v.torque_aero, &centre.cross(&force)) < 1e-14, "{:?}", p.v.torque_aero);
}

#[test]
fn drag_turns_with_the_attitude_and_the_air_rotates_with_the_earth() {
    // a yaw of 30°: the flow meets +x and −y faces; the air's velocity ω_E ẑ × r is removed
    let yaw = 30f64.to_radians();
    let mut p: P = plant(|v| {
        six_u(v);
        v.init_euler321_yaw = yaw;
        v.rho = 1e-12;
        v.v = Vector3::new(0.0, 7600.0, 0.0);
    });
    p.outputs(0.0).unwrap();
    let (sy, cy) = yaw.sin_cos();
    let a = Matrix3::new(cy, sy, 0.0, -sy, cy, 0.0, 0.0, 0.0, 1.0); // body-from-R of a 321 yaw alone
    let v_rel = Vector3::new(0.0, 7600.0 - 7.292115e-5 * 6_878_137.0, 0.0);
    let vb = a * v_rel;
    let (s, vh) = (vb.norm(), vb.normalize());
    let qd = 0.5 * 1e-12 * s * s * 2.2;
    let off = Vector3::new(0.01, -0.02, 0.03);
    let mut force = Vector3::zeros();
    let mut torque = Vector3::zeros();
    for (area, n, c) in [
        (0.06, Vector3::x(), Vector3::new(0.05, 0.0, 0.0)),
        (0.06, -Vector3::x(), Vector3::new(-0.05, 0.0, 0.0)),
        (0.03, Vector3::y(), Vector3::new(0.0, 0.1, 0.0)),
        (0.03, -Vector3::y(), Vector3::new(0.0, -0.1, 0.0)),
    ] {
        let cos = n.dot(&vh);
        if cos > 0.0 {
            let fi = -vh * (qd * area * cos);
            force += fi;
            torque += (c - off).cross(&fi);
        }
    }
    assert!(rel_err(&p.v.force_aero, &force) < 1e-12, "{:?} vs {:?}", p.v.force_aero, force);
    assert!(rel_err(&p.v.torque_aero, &torque) < 1e-12);
    assert!(rel_err(&p.v.torque_ext, &(torque + p.v.torque_srp)) < 1e-12);
}

#[test]
fn solar_pressure_on_the_top_face_and_its_shadow() {
    // sun along +z body (the sun far away along +z of R): only the +z face is lit, at normal incidence
    let mut p: P = plant(|v| {
        six_u(v);
        v.sun_eci = Vector3::z();
        v.r = Vector3::new(0.0, 0.0, -6_878_137.0);
    });
    p.outputs(0.0).unwrap();
    let to_sun: Vector3<f64> = Vector3::new(0.0, 0.0, 149_597_870_700.0 + 6_878_137.0);
    let (d, s) = (to_sun.norm(), to_sun.normalize());
    let pr = 1361.0 / 299_792_458.0 * (149_597_870_700.0_f64 / d).powi(2);
    let n = Vector3::z();
    let cos = n.dot(&s);
    let force = -(s * (1.0 - 0.3) + n * (2.0 * (0.3 * cos + 0.2 / 3.0))) * (pr * 0.02 * cos);
    let centre = Vector3::new(-0.01, 0.02, 0.15 - 0.03);
    assert!(rel_err(&p.v.force_srp, &force) < 1e-12, "{:?} vs {:?}", p.v.force_srp, force);
    assert!(rel_err(&p.v.torque_srp, &centre.cross(&force)) < 1e-12);
    // half the disk hidden halves it; the umbra removes it
    p.v.eclipse = 0.5;
    p.outputs(0.0).unwrap();
    assert!(rel_err(&p.v.force_srp, &(force * 0.5)) < 1e-12);
    p.v.eclipse = 0.0;
    p.outputs(0.0).unwrap();
    assert_eq!(p.v.force_srp, Vector3::zeros());
}

#[test]
fn gravity_gradient_from_the_input_position_equals_the_circular_orbits() {
    let setup = |v: &mut AttitudePlantVars| {
        (v.init_euler321_roll, v.init_euler321_pitch, v.init_euler321_yaw) = (0.3, -0.4, 1.0);
        v.gg_enable = 1;
    };
    let mut textbook: P = plant(setup);
    let mut world: P = plant(|v| {
        setup(v);
        v.environment_inputs = 1;
        v.r = Vector3::new(7078137.0, 0.0, 0.0);
        v.b_eci = Vector3::new(0.0, 0.0, 2e-5);
    });
    let v = &textbook.v;
    let orbit = CircularOrbit { mu: v.mu, radius: v.orbit_radius, inclination: v.orbit_inclination, arg_lat0: v.orbit_arg_lat0, dipole: v.earth_dipole };
    for t in [0.0, 100.0, 1234.5] {
        world.v.r = orbit.r_hat(t) * orbit.radius;
        textbook.outputs(t).unwrap();
        world.outputs(t).unwrap();
        assert!(rel_err(&world.v.torque_gg, &textbook.v.torque_gg) < 1e-12, "t = {t}");
        assert!(textbook.v.torque_gg.norm() > 1e-6);
    }
}

#[test]
fn residual_dipole_torque_is_m_cross_b_in_body_axes() {
    let b_eci = Vector3::new(2e-5, -1e-5, 3e-5);
    let mut p: P = plant(|v| {
        v.environment_inputs = 1;
        v.r = Vector3::new(0.0, 7e6, 0.0);
        v.b_eci = b_eci;
        v.residual_dipole = Vector3::new(0.05, 0.0, -0.02);
        v.init_euler321_pitch = 0.7;
    });
    p.outputs(0.0).unwrap();
    let expect = Vector3::new(0.05, 0.0, -0.02).cross(&p.v.b_body);
    assert!(rel_err(&p.v.torque_residual, &expect) < 1e-15 && expect.norm() > 1e-7);
    assert!((p.v.b_body.norm() - b_eci.norm()).abs() < 1e-18);
    assert_eq!(p.v.torque_ext, expect);
}

#[test]
fn an_unconnected_field_or_sun_is_refused_with_the_reason() {
    let mut p: P = plant(six_u);
    p.v.b_eci = Vector3::zeros();
    assert!(p.outputs(0.0).unwrap_err().contains("b_eci"));
    p.v.b_eci = Vector3::z() * 1e-5;
    p.v.sun_eci = Vector3::zeros();
    assert!(p.outputs(0.0).unwrap_err().contains("sun_eci"));
    p.v.sun_eci = Vector3::x();
    p.v.eclipse = 1.5;
    assert!(p.outputs(0.0).unwrap_err().contains("eclipse"));
}

#[test]
fn an_unconnected_position_is_refused_with_the_reason() {
    let mut p: P = plant(|v| v.init_w.x = 0.01);
    p.v.environment_inputs = 1;
    p.initialize(&Default::default()).unwrap();
    // never set (r and b_eci at their start value 0): the state outputs are read, the budget is 0, and a
    // step refuses the inputs
    p.outputs(0.0).unwrap();
    assert_eq!((p.v.w.x, p.v.torque_gg, p.v.b_body), (0.01, Vector3::zeros(), Vector3::zeros()));
    assert!(p.step(0.0, 0.1).unwrap_err().contains("input r"));
    // a field without a position is a wiring error, refused at once
    p.v.b_eci = Vector3::z() * 1e-5;
    let e = p.outputs(0.0).unwrap_err();
    assert!(e.contains("input r") && e.contains("connected"), "{e}");
}

#[test]
fn the_papers_plant_is_unchanged_by_zero_facets_and_dipole() {
    // the default (environment_inputs = 0, no facets, no residual dipole): the budget outputs are the
    // gravity gradient alone and the total external torque is bit for bit the generator's + gg
    let mut p: P = plant(|v| {
        v.gg_enable = 1;
        v.dist_const = Vector3::new(1e-4, 0.0, -2e-4);
        (v.init_euler321_roll, v.init_euler321_pitch) = (0.2, 0.1);
    });
    p.outputs(5.0).unwrap();
    assert_eq!(p.v.torque_aero, Vector3::zeros());
    assert_eq!(p.v.torque_srp, Vector3::zeros());
    assert_eq!(p.v.torque_residual, Vector3::zeros());
    assert_eq!(p.v.torque_ext, Vector3::new(1e-4, 0.0, -2e-4) + p.v.torque_gg);
}
