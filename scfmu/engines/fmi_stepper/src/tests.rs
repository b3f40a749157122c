//! The stepper against closed forms, on small units written here: exponential decay (both methods), a
//! threshold crossing and a bouncing ball (state events located against the analytic crossing times), a
//! time event between communication points, a step event asked by `completedIntegratorStep`, and a unit
//! that asks to terminate.

use crate::{Method, Settings, Stepper, Stop, Unit};

/// x' = -a·x (one state per entry of `x`); indicator x0 - level (none when `level` is None); at a state
/// event x0 is multiplied by `jump`; a time event at `t_event` sets a to `a2`; `completedIntegratorStep`
/// asks for an event once after `step_event`; `terminate_at`: the event iteration asks to terminate.
/// With `ball`: x = (height, velocity), x' = (v, -g), indicator = height, at a bounce v ← -e·v.
struct Toy {
    t: f64,
    x: Vec<f64>,
    a: f64,
    a2: f64,
    level: Option<f64>,
    jump: f64,
    t_event: Option<f64>,
    ball: Option<(f64, f64)>,
    step_event: Option<f64>,
    terminate_at_event: bool,
    event_times: Vec<f64>,
    step_events: usize,
}

impl Toy {
    fn decay(x0: f64, a: f64) -> Toy {
        Toy {
            t: 0.0,
            x: vec![x0],
            a,
            a2: a,
            level: None,
            jump: 1.0,
            t_event: None,
            ball: None,
            step_event: None,
            terminate_at_event: false,
            event_times: vec![],
            step_events: 0,
        }
    }
}

impl Unit for Toy {
    fn set_time(&mut self, t: f64) -> i32 {
        self.t = t;
        0
    }
    fn set_states(&mut self, x: &[f64]) -> i32 {
        self.x.copy_from_slice(x);
        0
    }
    fn get_states(&mut self, x: &mut [f64]) -> i32 {
        x.copy_from_slice(&self.x);
        0
    }
    fn derivatives(&mut self, dx: &mut [f64]) -> i32 {
        if let Some((g, _)) = self.ball {
            (dx[0], dx[1]) = (self.x[1], -g);
        } else {
            for (d, x) in dx.iter_mut().zip(&self.x) {
                *d = -self.a * x;
            }
        }
        0
    }
    fn indicators(&mut self, z: &mut [f64]) -> i32 {
        z[0] = if self.ball.is_some() {
            self.x[0]
        } else {
            self.x[0] - self.level.unwrap()
        };
        0
    }
    fn completed(&mut self) -> (i32, bool, bool) {
        let enter = self.step_event.is_some_and(|ts| self.t >= ts);
        if enter {
            self.step_event = None;
            self.step_events += 1;
        }
        (0, enter, false)
    }
    fn enter_event_mode(&mut self) -> i32 {
        0
    }
    fn update(&mut self) -> (i32, bool, bool, Option<f64>) {
        if self.ball.is_none() {
            self.event_times.push(self.t);
        }
        if self.terminate_at_event {
            return (0, false, true, None);
        }
        if self.t_event.is_some_and(|te| self.t >= te) {
            self.t_event = None;
            self.a = self.a2;
        }
        if let Some((_, e)) = self.ball {
            if self.x[0] <= 0.0 && self.x[1] < 0.0 {
                self.event_times.push(self.t); // a bounce (the rise through 0 after it is an event too)
                self.x[1] *= -e;
            }
        } else if let Some(level) = self.level {
            if self.x[0] <= level {
                self.x[0] *= self.jump;
                self.level = Some(-1.0); // one crossing
            }
        }
        (0, false, false, self.t_event)
    }
    fn enter_continuous_mode(&mut self) -> i32 {
        0
    }
}

fn settings(method: Method, rtol: f64, max_step: f64) -> Settings {
    Settings {
        method,
        rtol,
        atol: rtol * 1e-2,
        max_step,
    }
}

/// Steps `u` on the grid t_k = k·dt to `stop`; the stepper.
fn run(u: &mut Toy, s: Settings, nz: usize, dt: f64, stop: f64) -> Result<Stepper, Stop> {
    let mut st = Stepper::new(u.x.len(), nz, s, u.t_event);
    let n = (stop / dt).round() as usize;
    for k in 0..n {
        st.step(u, k as f64 * dt, (k + 1) as f64 * dt)?;
    }
    Ok(st)
}

#[test]
fn exponential_decay_under_dormand_prince_meets_its_tolerance() {
    let mut u = Toy::decay(2.0, 1.5);
    let st = run(&mut u, settings(Method::DormandPrince, 1e-10, 0.0), 0, 0.1, 4.0).unwrap();
    let exact = 2.0 * (-1.5f64 * 4.0).exp();
    assert!(
        (st.states()[0] - exact).abs() < 1e-9 * exact,
        "{} vs {exact}",
        st.states()[0]
    );
    assert!(
        st.accepted > 40 && st.rejected < st.accepted,
        "{} / {}",
        st.accepted,
        st.rejected
    );
}

#[test]
fn exponential_decay_under_rk4_is_the_methods_amplification_factor() {
    // RK4 on x' = -a x multiplies x by R(-a h) = 1 - ah + (ah)²/2 - (ah)³/6 + (ah)⁴/24 per step; max_step 0.025
    // splits each communication step of 0.1 in four
    let (a, h, n) = (1.5f64, 0.025f64, 160);
    let mut u = Toy::decay(2.0, a);
    let st = run(&mut u, settings(Method::Rk4, 1e-10, h), 0, 0.1, 4.0).unwrap();
    let z = -a * h;
    let r = 1.0 + z + z * z / 2.0 + z.powi(3) / 6.0 + z.powi(4) / 24.0;
    let want = 2.0 * r.powi(n);
    assert_eq!(st.accepted, n as usize);
    assert!(
        (st.states()[0] - want).abs() < 1e-13 * want,
        "{} vs {want}",
        st.states()[0]
    );
    // and it is fourth order: the error against e^{-at} is of the size of h⁴
    let exact = 2.0 * (-a * 4.0).exp();
    assert!((st.states()[0] - exact).abs() < 1e-6 * exact);
}

#[test]
fn a_threshold_crossing_is_located_at_the_analytic_time_by_both_methods() {
    // x' = -x from 1 crosses 0.5 at ln 2 (between communication points 0.6 and 0.7); x then halves to 0.25
    for (method, tol) in [(Method::DormandPrince, 1e-9), (Method::Rk4, 1e-6)] {
        let mut u = Toy::decay(1.0, 1.0);
        (u.level, u.jump) = (Some(0.5), 0.5);
        let st = run(&mut u, settings(method, 1e-11, 0.0), 1, 0.1, 2.0).unwrap();
        assert_eq!(u.event_times.len(), 1, "{method:?}: {:?}", u.event_times);
        let t_cross = 2f64.ln();
        assert!(
            (u.event_times[0] - t_cross).abs() < tol,
            "{method:?}: {} vs {t_cross}",
            u.event_times[0]
        );
        let exact = 0.25 * (-(2.0 - t_cross)).exp();
        assert!(
            (st.states()[0] - exact).abs() < 1e-4 * exact,
            "{method:?}: {}",
            st.states()[0]
        );
    }
}

#[test]
fn a_bouncing_ball_bounces_at_the_analytic_times() {
    // dropped from 1 m: first contact at √(2h/g); leaving at e·v it is back after 2·e·v/g
    let (g, e, h0) = (9.81f64, 0.8f64, 1.0f64);
    let mut u = Toy::decay(0.0, 0.0);
    u.x = vec![h0, 0.0];
    u.ball = Some((g, e));
    run(&mut u, settings(Method::DormandPrince, 1e-10, 0.0), 1, 0.05, 1.5).unwrap();
    let t1 = (2.0 * h0 / g).sqrt();
    let t2 = t1 + 2.0 * e * g * t1 / g;
    assert!(u.event_times.len() >= 2, "{:?}", u.event_times);
    assert!((u.event_times[0] - t1).abs() < 1e-9, "{} vs {t1}", u.event_times[0]);
    assert!((u.event_times[1] - t2).abs() < 1e-9, "{} vs {t2}", u.event_times[1]);
}

#[test]
fn a_time_event_between_communication_points_is_taken_at_its_time() {
    // a = 1 until 0.2345, then 3: x(1) = e^{-0.2345}·e^{-3·0.7655}
    // (RK4's global error at h = 0.01: about Σ (a·h)⁵/120 over the steps, 1.6e-8 relative here)
    for (method, tol) in [(Method::DormandPrince, 1e-8), (Method::Rk4, 5e-8)] {
        let mut u = Toy::decay(1.0, 1.0);
        (u.a2, u.t_event) = (3.0, Some(0.2345));
        let st = run(&mut u, settings(method, 1e-11, 0.01), 0, 0.1, 1.0).unwrap();
        assert_eq!(u.event_times, vec![0.2345], "{method:?}");
        let exact = (-0.2345f64).exp() * (-3.0 * 0.7655f64).exp();
        assert!(
            (st.states()[0] - exact).abs() < tol * exact,
            "{method:?}: {}",
            st.states()[0]
        );
    }
}

#[test]
fn an_overdue_time_event_is_taken_at_once() {
    // the unit's next event time lies before the step's start (a caller that skipped it): taken at t = 0.5
    let mut u = Toy::decay(1.0, 1.0);
    (u.a2, u.t_event) = (3.0, Some(0.2));
    let mut st = Stepper::new(1, 0, settings(Method::DormandPrince, 1e-11, 0.0), Some(0.2));
    st.step(&mut u, 0.5, 1.0).unwrap();
    assert_eq!(u.event_times, vec![0.5]);
    // x(0.5) = 1 (the unit's state where the stepper starts), then the new rate: x(1) = e^{-3·0.5}
    let exact = (-1.5f64).exp();
    assert!(
        (st.states()[0] - exact).abs() < 1e-9 * exact,
        "{} vs {exact}",
        st.states()[0]
    );
}

#[test]
fn a_step_event_runs_the_event_iteration_and_termination_stops_at_that_time() {
    let mut u = Toy::decay(1.0, 1.0);
    u.step_event = Some(0.5);
    run(&mut u, settings(Method::Rk4, 1e-10, 0.0), 0, 0.1, 1.0).unwrap();
    assert_eq!(u.step_events, 1);
    assert_eq!(u.event_times.len(), 1);
    assert!((u.event_times[0] - 0.5).abs() < 1e-12, "{:?}", u.event_times);
    let mut u = Toy::decay(1.0, 1.0);
    (u.step_event, u.terminate_at_event) = (Some(0.3), true);
    let mut st = Stepper::new(1, 0, settings(Method::DormandPrince, 1e-8, 0.0), None);
    let r = (0..10).try_for_each(|k| st.step(&mut u, k as f64 * 0.1, (k + 1) as f64 * 0.1).map(|_| ()));
    assert_eq!(r, Err(Stop::Terminate));
    assert!(st.t >= 0.3 && st.t <= 0.4 + 1e-12, "{}", st.t);
}

#[cfg(unix)]
#[test]
fn a_library_without_the_model_exchange_functions_names_the_first_missing_one() {
    use crate::{dynlib, Table};
    let libm = if cfg!(target_os = "macos") {
        "/usr/lib/libSystem.B.dylib"
    } else {
        "libm.so.6"
    };
    let h = dynlib::open(libm).expect("the C math library");
    // SAFETY: the table is not built (the first function is missing), so nothing is called
    let e = unsafe { Table::load(h, true) }.err().expect("no FMI functions in libm");
    assert_eq!(e, "the unit's library has no fmi3SetTime");
    // SAFETY: as above
    assert!(unsafe { Table::from_slots(false, [std::ptr::null(); 9]) }.is_none());
}
