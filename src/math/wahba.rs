//! Static attitude determination from vector observations (Wahba's problem): TRIAD and Davenport's
//! q-method, in the project's convention (scalar-first quaternion q of the body frame B relative to the
//! reference frame R, A(q) maps R-components into B-components: an exact observation is b = A r).
//!
//! - TRIAD (Black 1964; Markley & Crassidis 2014, Sec. 5.2): two orthonormal triads, one per frame,
//!   built on an anchor vector (matched exactly) and the normalised cross product:
//!   t1 = v1, t2 = (v1 × v2)/|v1 × v2|, t3 = t1 × t2, A = [t1_B t2_B t3_B] [t1_R t2_R t3_R]ᵀ.
//! - Davenport's q-method (Markley & Crassidis 2014, Sec. 5.3): Wahba's loss
//!   L(A) = ½ Σ a_i |b_i − A r_i|² = λ0 − tr(A Bᵀ), λ0 = Σ a_i, B = Σ a_i b_i r_iᵀ, is minimised by the
//!   eigenvector of the largest eigenvalue λ_max of the symmetric 4×4 matrix
//!   K = [[S − σ I, z], [zᵀ, σ]] (vector part first), S = B + Bᵀ, σ = tr B, z = Σ a_i b_i × r_i,
//!   and the minimum loss is λ0 − λ_max. The eigen-decomposition (nalgebra's symmetric QR iteration) is
//!   the robust way QUEST's characteristic-polynomial iteration approximates; it needs no sequential
//!   rotations and has no singularity at 180°.
//!
//! Observability is checked before solving: at least two observations of positive weight whose
//! directions are at least `min_sep` apart (in both frames), every vector finite and non-zero.

use nalgebra::{Matrix3, Matrix4, Quaternion, SymmetricEigen, Vector3};

use crate::math::attitude::{attitude_matrix, quat_from_dcm};

/// One weighted observation: a direction measured in body axes and the same direction in the
/// reference frame (neither needs unit length; both are normalised).
#[derive(Clone, Copy, Debug)]
pub struct Observation {
    pub body: Vector3<f64>,
    pub reference: Vector3<f64>,
    pub weight: f64,
}

/// Unit vector of v; the message names the vector when it is zero or not finite.
pub fn unit(name: &str, v: &Vector3<f64>) -> Result<Vector3<f64>, String> {
    let n = v.norm();
    if !n.is_finite() || n < 1e-300 {
        return Err(format!(
            "vector {name} = [{}, {}, {}] has no direction (zero or not finite)",
            v.x, v.y, v.z
        ));
    }
    Ok(v / n)
}

/// |u × v| of unit vectors: the sine of the angle between the directions.
fn sin_between(u: &Vector3<f64>, v: &Vector3<f64>) -> f64 {
    u.cross(v).norm()
}

/// Checks that the pair (u, v) of unit vectors is at least `min_sep` rad apart (and as far from
/// antiparallel): sin of the angle ≥ sin(min_sep).
fn check_pair(what: &str, u: &Vector3<f64>, v: &Vector3<f64>, min_sep: f64) -> Result<(), String> {
    let s = sin_between(u, v);
    if s < min_sep.sin() {
        return Err(format!(
            "{what} are (anti)parallel: angle {:.3e} rad from collinear, at least min_separation = {min_sep} rad needed",
            s.asin()
        ));
    }
    Ok(())
}

/// TRIAD attitude matrix from the anchor observation (b1, r1), matched exactly, and a second one
/// (b2, r2) that fixes the rotation about it. Vectors are normalised; collinear pairs are refused.
pub fn triad(
    b1: &Vector3<f64>,
    b2: &Vector3<f64>,
    r1: &Vector3<f64>,
    r2: &Vector3<f64>,
    min_sep: f64,
) -> Result<Matrix3<f64>, String> {
    let (b1, b2) = (unit("body 1", b1)?, unit("body 2", b2)?);
    let (r1, r2) = (unit("reference 1", r1)?, unit("reference 2", r2)?);
    check_pair("the two body-frame observations", &b1, &b2, min_sep)?;
    check_pair("the two reference vectors", &r1, &r2, min_sep)?;
    let triad = |v1: Vector3<f64>, v2: Vector3<f64>| {
        let t2 = v1.cross(&v2).normalize();
        Matrix3::from_columns(&[v1, t2, v1.cross(&t2)])
    };
    Ok(triad(b1, b2) * triad(r1, r2).transpose())
}

/// Davenport's K matrix (vector part first) of normalised observations, and λ0 = Σ a_i.
pub fn davenport_k(obs: &[(Vector3<f64>, Vector3<f64>, f64)]) -> (Matrix4<f64>, f64) {
    let mut b = Matrix3::zeros();
    let mut z = Vector3::zeros();
    let mut lambda0 = 0.0;
    for (bi, ri, a) in obs {
        b += bi * ri.transpose() * *a;
        z += bi.cross(ri) * *a;
        lambda0 += a;
    }
    let s = b + b.transpose();
    let sigma = b.trace();
    let mut k = Matrix4::zeros();
    k.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(s - Matrix3::identity() * sigma));
    k.fixed_view_mut::<3, 1>(0, 3).copy_from(&z);
    k.fixed_view_mut::<1, 3>(3, 0).copy_from(&z.transpose());
    k[(3, 3)] = sigma;
    (k, lambda0)
}

/// A normalised observation in use: (body direction, reference direction, weight).
type Used = (Vector3<f64>, Vector3<f64>, f64);

/// The solution of Wahba's problem: the quaternion (scalar first, q_w ≥ 0) and the minimum loss.
#[derive(Clone, Copy, Debug)]
pub struct Solution {
    pub q: Quaternion<f64>,
    /// L = ½ Σ a_i |b_i − A(q) r_i|² with the given weights (unit vectors).
    pub loss: f64,
}

/// Davenport's q-method over the observations of positive weight (zero weights are skipped).
/// Refuses fewer than two used observations, non-finite or zero vectors, negative or non-finite
/// weights, and observation sets whose used directions are all within `min_sep` of one line (in
/// either frame), where the attitude about that line is undetermined.
pub fn q_method(obs: &[Observation], names: &[&str], min_sep: f64) -> Result<Solution, String> {
    let mut used = Vec::with_capacity(obs.len());
    for (o, name) in obs.iter().zip(names) {
        if !(o.weight.is_finite() && o.weight >= 0.0) {
            return Err(format!("weight of {name} = {} must be finite and >= 0", o.weight));
        }
        if o.weight == 0.0 {
            continue;
        }
        used.push((
            unit(&format!("{name} (body)"), &o.body)?,
            unit(&format!("{name} (reference)"), &o.reference)?,
            o.weight,
        ));
    }
    if used.len() < 2 {
        return Err(format!(
            "{} observation(s) of positive weight: at least two are needed",
            used.len()
        ));
    }
    // at least one pair must span a plane, in both frames
    let spans = |pick: fn(&Used) -> Vector3<f64>| {
        let mut best = 0.0f64;
        for i in 0..used.len() {
            for j in i + 1..used.len() {
                best = best.max(sin_between(&pick(&used[i]), &pick(&used[j])));
            }
        }
        best
    };
    for (frame, s) in [
        ("body-frame observations", spans(|o| o.0)),
        ("reference vectors", spans(|o| o.1)),
    ] {
        if s < min_sep.sin() {
            return Err(format!(
                "the {frame} are all (anti)parallel: largest angle from collinear {:.3e} rad, at least min_separation = {min_sep} rad needed",
                s.asin()
            ));
        }
    }
    let (k, lambda0) = davenport_k(&used);
    let eig = SymmetricEigen::new(k);
    let imax = eig.eigenvalues.imax();
    let v = eig.eigenvectors.column(imax);
    let sign = if v[3] < 0.0 { -1.0 } else { 1.0 };
    let q = Quaternion::new(v[3], v[0], v[1], v[2]) * (sign / v.norm());
    if !q.coords.iter().all(|x| x.is_finite()) {
        return Err("the eigen-decomposition of Davenport's K matrix did not give a finite quaternion".into());
    }
    // the loss from the residuals (not λ0 − λ_max, which loses digits to cancellation when the loss is small)
    let a = attitude_matrix(&q);
    let loss = 0.5 * used.iter().map(|(b, r, w)| w * (b - a * r).norm_squared()).sum::<f64>();
    debug_assert!((loss - (lambda0 - eig.eigenvalues[imax])).abs() < 1e-9 * lambda0.max(1.0));
    Ok(Solution { q, loss })
}

/// The scalar-first quaternion with q_w ≥ 0 of an attitude matrix.
pub fn quat_nonneg(a: &Matrix3<f64>) -> Quaternion<f64> {
    let q = quat_from_dcm(a);
    if q.w < 0.0 {
        -q
    } else {
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::attitude::quat_from_euler321;

    fn obs(q: &Quaternion<f64>, r: Vector3<f64>, w: f64) -> Observation {
        Observation {
            body: attitude_matrix(q) * r,
            reference: r,
            weight: w,
        }
    }

    fn close(q: &Quaternion<f64>, p: &Quaternion<f64>) -> f64 {
        (q.coords - p.coords).norm().min((q.coords + p.coords).norm())
    }

    #[test]
    fn exact_observations_give_the_true_attitude() {
        for (i, q) in [
            quat_from_euler321(0.3, -0.4, 2.0),
            quat_from_euler321(3.0, 1.2, -2.9),
            Quaternion::new(0.0, 1.0, 0.0, 0.0),
        ]
        .iter()
        .enumerate()
        {
            let r1 = Vector3::new(1.0, 2.0, -0.5);
            let r2 = Vector3::new(-0.3, 0.1, 2.0);
            let a = triad(
                &(attitude_matrix(q) * r1 * 3.0),
                &(attitude_matrix(q) * r2),
                &r1,
                &r2,
                1e-3,
            )
            .unwrap();
            assert!(close(&quat_nonneg(&a), q) < 1e-14, "case {i} triad");
            let s = q_method(
                &[obs(q, r1, 0.7), obs(q, r2, 0.3), obs(q, Vector3::x(), 0.0)],
                &["a", "b", "c"],
                1e-3,
            )
            .unwrap();
            assert!(close(&s.q, q) < 1e-14, "case {i} q-method {:?}", s.q);
            assert!(s.q.w >= 0.0 && s.loss < 1e-28, "{}", s.loss);
        }
    }

    #[test]
    fn loss_of_inconsistent_observations_is_the_closed_form() {
        // two reference vectors 90° apart, body vectors 90° + 2ε apart symmetrically about the same
        // bisector, equal weights: the optimum splits the error, each residual is 2 sin(ε/2),
        // L = ½ (a + a) 4 sin²(ε/2) = 4 a sin²(ε/2)
        let eps: f64 = 0.01;
        let (r1, r2) = (Vector3::x(), Vector3::y());
        let (b1, b2) = (
            Vector3::new((-eps).cos(), (-eps).sin(), 0.0),
            Vector3::new(-(eps).sin(), (eps).cos(), 0.0),
        );
        let a = 0.5;
        let s = q_method(
            &[
                Observation {
                    body: b1,
                    reference: r1,
                    weight: a,
                },
                Observation {
                    body: b2,
                    reference: r2,
                    weight: a,
                },
            ],
            &["1", "2"],
            1e-3,
        )
        .unwrap();
        assert!(
            (s.loss - 4.0 * a * (eps / 2.0).sin().powi(2)).abs() < 1e-15,
            "{}",
            s.loss
        );
        assert!(close(&s.q, &Quaternion::new(1.0, 0.0, 0.0, 0.0)) < 1e-14, "{:?}", s.q);
        // TRIAD anchors the first vector: the rotation is −ε about z (b1 = A r1 exactly)
        let at = triad(&b1, &b2, &r1, &r2, 1e-3).unwrap();
        assert!((at * r1 - b1).norm() < 1e-15);
    }

    #[test]
    fn degenerate_geometry_is_refused_with_a_reason() {
        let q = quat_from_euler321(0.1, 0.2, 0.3);
        let r = Vector3::new(1.0, 1.0, 0.0);
        let e = triad(
            &(attitude_matrix(&q) * r),
            &(attitude_matrix(&q) * r * -2.0),
            &r,
            &(r * -2.0),
            1e-3,
        )
        .unwrap_err();
        assert!(e.contains("(anti)parallel"), "{e}");
        let e = triad(&Vector3::zeros(), &Vector3::x(), &Vector3::x(), &Vector3::y(), 1e-3).unwrap_err();
        assert!(e.contains("body 1") && e.contains("no direction"), "{e}");
        let e = triad(
            &Vector3::new(f64::NAN, 0.0, 0.0),
            &Vector3::x(),
            &Vector3::x(),
            &Vector3::y(),
            1e-3,
        )
        .unwrap_err();
        assert!(e.contains("no direction"), "{e}");
        let e = q_method(&[obs(&q, r, 1.0), obs(&q, Vector3::z(), 0.0)], &["sun", "mag"], 1e-3).unwrap_err();
        assert!(e.contains("1 observation(s)"), "{e}");
        let e = q_method(
            &[obs(&q, r, 1.0), obs(&q, r * 3.0, 1.0), obs(&q, -r, 1.0)],
            &["a", "b", "c"],
            1e-3,
        )
        .unwrap_err();
        assert!(e.contains("all (anti)parallel"), "{e}");
        let e = q_method(&[obs(&q, r, -1.0), obs(&q, Vector3::z(), 1.0)], &["sun", "mag"], 1e-3).unwrap_err();
        assert!(e.contains("weight of sun"), "{e}");
        // just above the separation limit it solves
        let r2 = Vector3::new(1.0, 1.0, 2e-3 * 2f64.sqrt());
        assert!(q_method(&[obs(&q, r, 1.0), obs(&q, r2, 1.0)], &["a", "b"], 1e-3).is_ok());
    }

    #[test]
    fn rotation_by_180_degrees_is_found() {
        // QUEST's classic singularity (q_w = 0) is no problem for the eigen-decomposition
        let q = Quaternion::new(0.0, 0.0, 0.6, 0.8);
        let s = q_method(
            &[
                obs(&q, Vector3::x(), 1.0),
                obs(&q, Vector3::y(), 2.0),
                obs(&q, Vector3::z(), 0.5),
            ],
            &["1", "2", "3"],
            1e-3,
        )
        .unwrap();
        assert!(close(&s.q, &q) < 1e-14, "{:?}", s.q);
    }
}
