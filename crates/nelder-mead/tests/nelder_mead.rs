//! Tests of `nelder_mead`: known optima, scipy's results on the same problems
//! (`fixtures/nelder_mead/nm_reference.json`, made by `make_nm_reference.py` in that folder),
//! bounds, NaN regions, errors, limits, settings validation and Lagarias' tie-breaking.
//!
//! `cargo test -p nelder-mead --test nelder_mead -- --nocapture` prints the evaluation counts
//! side by side with scipy's.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use nelder_mead::{
    Bounds, Coefficients, Error, InitialSteps, NelderMead, Outcome, ProblemError, SettingsError,
    Start, Termination,
};
use serde::Deserialize;
use std::cell::Cell;
use std::path::Path;

// ---- problems: the same operations in the same order as in make_nm_reference.py ----

fn rosenbrock(x: &[f64]) -> f64 {
    let mut s = 0.0;
    for i in 0..x.len() - 1 {
        let a = x[i + 1] - x[i] * x[i];
        let b = 1.0 - x[i];
        s += 100.0 * a * a + b * b;
    }
    s
}

fn powell_singular(x: &[f64]) -> f64 {
    let t1 = x[0] + 10.0 * x[1];
    let t2 = x[2] - x[3];
    let t3 = x[1] - 2.0 * x[2];
    let t4 = x[0] - x[3];
    let q3 = t3 * t3;
    let q4 = t4 * t4;
    t1 * t1 + 5.0 * t2 * t2 + q3 * q3 + 10.0 * q4 * q4
}

const QUAD_CENTER: [f64; 3] = [1.0, -2.0, 0.5];

fn shifted_quadratic(x: &[f64]) -> f64 {
    let d0 = x[0] - QUAD_CENTER[0];
    let d1 = x[1] - QUAD_CENTER[1];
    let d2 = x[2] - QUAD_CENTER[2];
    3.5 + d0 * d0 + 4.0 * d1 * d1 + 0.25 * d2 * d2 + 0.5 * d0 * d1
}

/// Unconstrained minimum (3, −1, 5, 0.5); inside [`bounded_box`] it is (2, 0, 1, 0.5), f = 18.
fn bounded_quadratic(x: &[f64]) -> f64 {
    let a = x[0] - 3.0;
    let b = x[1] + 1.0;
    let c = x[2] - 5.0;
    let d = x[3] - 0.5;
    a * a + b * b + c * c + d * d
}

/// x0 ∈ [−1, 2] (both sides), x1 ≥ 0 (lower only), x2 ≤ 1 (upper only), x3 free.
fn bounded_box() -> Bounds {
    let inf = f64::INFINITY;
    Bounds::new(vec![-1.0, 0.0, -inf, -inf], vec![2.0, inf, 1.0, inf]).unwrap()
}

/// (ln x0 − 1)² + (x1 − x0)²: NaN for x0 < 0, +∞ at x0 = 0, minimum 0 at (e, e).
fn log_valley(x: &[f64]) -> f64 {
    let l = if x[0] > 0.0 {
        x[0].ln()
    } else if x[0] == 0.0 {
        f64::NEG_INFINITY
    } else {
        f64::NAN
    };
    let a = l - 1.0;
    let b = x[1] - x[0];
    a * a + b * b
}

fn problem(name: &str) -> fn(&[f64]) -> f64 {
    match name {
        "rosenbrock" => rosenbrock,
        "powell_singular" => powell_singular,
        "shifted_quadratic" => shifted_quadratic,
        "bounded_quadratic" => bounded_quadratic,
        "log_valley" => log_valley,
        other => panic!("unknown problem {other} in the fixture"),
    }
}

fn tight() -> NelderMead {
    NelderMead::new()
        .with_x_tolerance(1e-8)
        .unwrap()
        .with_f_tolerance(1e-10)
        .unwrap()
        .with_max_evaluations(20_000)
        .unwrap()
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .fold(0.0, |m, (x, y)| f64::max(m, (x - y).abs()))
}

fn assert_near(outcome: &Outcome, x: &[f64], x_tol: f64, f: f64, f_tol: f64) {
    let dx = max_abs_diff(&outcome.x, x);
    assert!(
        dx <= x_tol,
        "x = {:?}, expected {x:?} (off by {dx:e})",
        outcome.x
    );
    assert!(
        (outcome.f - f).abs() <= f_tol,
        "f = {:e}, expected {f:e}",
        outcome.f
    );
}

// ---- scipy reference ----

#[derive(Deserialize)]
struct Fixture {
    scipy_version: String,
    cases: Vec<Case>,
}

#[derive(Deserialize)]
struct Case {
    name: String,
    problem: String,
    x0: Vec<f64>,
    initial_simplex: Option<Vec<Vec<f64>>>,
    bounds: Option<Vec<[Option<f64>; 2]>>,
    adaptive: bool,
    xatol: f64,
    fatol: f64,
    maxfev: usize,
    known_x: Option<Vec<f64>>,
    known_f: Option<f64>,
    /// scipy as shipped.
    scipy: ScipyResult,
    /// scipy with a stable `np.argsort`, i.e. with Lagarias' tie rules (see the generator).
    scipy_stable_sort: ScipyResult,
}

#[derive(Deserialize)]
struct ScipyResult {
    x: Vec<f64>,
    fun: f64,
    nit: usize,
    nfev: usize,
    status: i32,
}

fn fixture() -> Fixture {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/nelder_mead/nm_reference.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn run_case(case: &Case) -> Outcome {
    let mut settings = NelderMead::new()
        .with_x_tolerance(case.xatol)
        .unwrap()
        .with_f_tolerance(case.fatol)
        .unwrap()
        .with_max_evaluations(case.maxfev)
        .unwrap();
    if case.adaptive {
        settings = settings.with_adaptive_coefficients();
    }
    if let Some(b) = &case.bounds {
        let lower = b.iter().map(|[lo, _]| lo.unwrap_or(f64::NEG_INFINITY));
        let upper = b.iter().map(|[_, hi]| hi.unwrap_or(f64::INFINITY));
        settings = settings.with_bounds(Bounds::new(lower.collect(), upper.collect()).unwrap());
    }
    let start = match &case.initial_simplex {
        Some(s) => Start::Simplex(s.clone()),
        None => Start::Point(case.x0.clone()),
    };
    settings.minimize(problem(&case.problem), start).unwrap()
}

/// Against scipy as shipped: the same optimum, the same termination, at most 2× its
/// evaluations. Against scipy with Lagarias' tie rules (a stable sort) on unbounded problems,
/// where both use the same simplex, the same formulas and the same ordering: exactly the same
/// path (evaluation and iteration counts, x to rounding).
#[test]
fn matches_scipy_reference() {
    let fixture = fixture();
    assert!(fixture.cases.len() >= 10);
    println!(
        "Nelder-Mead vs scipy {} (nit: scipy counts from 1, ours shown +1; \
         'stable': scipy with a stable sort = Lagarias' tie rules)",
        fixture.scipy_version
    );
    println!(
        "{:<27} {:>9} {:>10} {:>11} {:>8} {:>9} {:>10} {:>10} {:>9}",
        "case",
        "nfev ours",
        "nfev scipy",
        "nfev stable",
        "nit ours",
        "nit scipy",
        "f ours",
        "f scipy",
        "|dx|"
    );
    for case in &fixture.cases {
        let ours = run_case(case);
        let dx = max_abs_diff(&ours.x, &case.scipy.x);
        println!(
            "{:<27} {:>9} {:>10} {:>11} {:>8} {:>9} {:>10.2e} {:>10.2e} {:>9.1e}",
            case.name,
            ours.evaluations,
            case.scipy.nfev,
            case.scipy_stable_sort.nfev,
            ours.iterations + 1,
            case.scipy.nit,
            ours.f,
            case.scipy.fun,
            dx
        );
        let name = &case.name;

        let expected = match case.scipy.status {
            0 => Termination::Converged,
            1 => Termination::MaxEvaluations,
            2 => Termination::MaxIterations,
            s => panic!("{name}: scipy status {s}"),
        };
        assert_eq!(ours.termination, expected, "{name}");
        assert!(ours.evaluations <= case.maxfev, "{name}");
        assert!(
            ours.evaluations <= 2 * case.scipy.nfev,
            "{name}: {} evaluations, scipy {}",
            ours.evaluations,
            case.scipy.nfev
        );
        assert_eq!(ours.steps.total(), ours.iterations, "{name}");

        if let (Some(x), Some(f)) = (&case.known_x, case.known_f) {
            // Powell's singular function is flat (quartic) at its minimum: x is only known to
            // about sqrt of the f accuracy there, but still far inside 1e-6.
            assert_near(&ours, x, 1e-6, f, 1e-12);
            assert!(max_abs_diff(&case.scipy.x, x) <= 1e-6, "{name}: fixture");
        }
        if case.bounds.is_none() {
            // Same path as scipy with Lagarias' tie rules.
            let stable = &case.scipy_stable_sort;
            assert_eq!(ours.evaluations, stable.nfev, "{name}: nfev");
            assert_eq!(ours.iterations + 1, stable.nit, "{name}: nit");
            let dx = max_abs_diff(&ours.x, &stable.x);
            assert!(dx <= 1e-12, "{name}: x differs from scipy's by {dx:e}");
            assert!((ours.f - stable.fun).abs() <= 1e-15 * (1.0 + stable.fun.abs()));
        } else {
            // Different bound handling (transformation here, clipping in scipy): the same
            // optimum, not the same path.
            assert!(dx <= 1e-6, "{name}: x differs from scipy's by {dx:e}");
        }
    }
}

// ---- known optima ----

#[test]
fn rosenbrock_2d_from_classic_start() {
    let out = tight().minimize(rosenbrock, [-1.2, 1.0]).unwrap();
    assert!(out.converged());
    assert_near(&out, &[1.0, 1.0], 1e-7, 0.0, 1e-14);
    assert_eq!(out.steps.total(), out.iterations);
    // A curved valley needs every kind of step.
    let s = out.steps;
    assert!(s.reflect > 0 && s.expand > 0 && s.contract_inside > 0 && s.contract_outside > 0);
    assert_eq!(out.simplex.len(), 3);
    assert_eq!(out.simplex[0], out.x);
    assert_eq!(out.simplex_values[0], out.f);
    assert!(out.simplex_values.windows(2).all(|w| w[0] <= w[1]));
}

#[test]
fn rosenbrock_5d_adaptive_and_10d_adaptive_beats_standard() {
    let out = tight()
        .with_adaptive_coefficients()
        .minimize(rosenbrock, [0.0; 5])
        .unwrap();
    assert!(out.converged());
    assert_near(&out, &[1.0; 5], 1e-6, 0.0, 1e-12);

    let standard = tight().minimize(rosenbrock, [-1.0; 10]).unwrap();
    let adaptive = tight()
        .with_adaptive_coefficients()
        .minimize(rosenbrock, [-1.0; 10])
        .unwrap();
    println!(
        "10-D Rosenbrock: standard {} evaluations, adaptive {}",
        standard.evaluations, adaptive.evaluations
    );
    assert_near(&standard, &[1.0; 10], 1e-6, 0.0, 1e-12);
    assert_near(&adaptive, &[1.0; 10], 1e-6, 0.0, 1e-12);
    assert!(adaptive.evaluations < standard.evaluations * 3 / 4);
}

#[test]
fn powell_singular_4d() {
    let out = tight()
        .minimize(powell_singular, [3.0, -1.0, 0.0, 1.0])
        .unwrap();
    assert!(out.converged());
    assert_near(&out, &[0.0; 4], 1e-6, 0.0, 1e-20);
}

#[test]
fn shifted_quadratic_known_point_and_value() {
    for settings in [tight(), tight().with_adaptive_coefficients()] {
        let out = settings.minimize(shifted_quadratic, [0.0; 3]).unwrap();
        assert!(out.converged());
        assert_near(&out, &QUAD_CENTER, 1e-7, 3.5, 1e-12);
    }
    // A start far away with absolute initial steps.
    let out = tight()
        .with_initial_steps(InitialSteps::Absolute(vec![1.0, -1.0, 2.0]))
        .unwrap()
        .minimize(shifted_quadratic, [50.0, 40.0, -30.0])
        .unwrap();
    assert!(out.converged());
    assert_near(&out, &QUAD_CENTER, 1e-7, 3.5, 1e-12);
}

#[test]
fn bounded_optimum_lies_on_the_bounds_and_only_feasible_points_are_evaluated() {
    let bounds = bounded_box();
    let infeasible = Cell::new(0);
    let calls = Cell::new(0);
    let objective = |x: &[f64]| {
        calls.set(calls.get() + 1);
        if !bounds.contains(x) {
            infeasible.set(infeasible.get() + 1);
        }
        bounded_quadratic(x)
    };
    let settings = tight().with_bounds(bounds.clone());
    // From inside, and from a start exactly on the upper bound of x0 and the lower of x1
    // (the initial steps there are reflected back into the box).
    for start in [[0.5, 1.0, -1.0, 0.0], [2.0, 0.0, 1.0, 0.0]] {
        let out = settings.minimize(objective, start).unwrap();
        assert!(out.converged(), "{start:?}: {:?}", out.termination);
        assert_near(&out, &[2.0, 0.0, 1.0, 0.5], 1e-7, 18.0, 1e-10);
        assert!(bounds.contains(&out.x));
        assert!(out.simplex.iter().all(|v| bounds.contains(v)));
    }
    assert!(calls.get() > 100);
    assert_eq!(infeasible.get(), 0, "the objective saw infeasible points");

    // Without the bounds the optimum is the unconstrained one: the bounds are what moved it.
    let free = tight()
        .minimize(bounded_quadratic, [0.5, 1.0, -1.0, 0.0])
        .unwrap();
    assert_near(&free, &[3.0, -1.0, 5.0, 0.5], 1e-6, 0.0, 1e-12);
}

#[test]
fn one_sided_bounds_inactive_optimum_is_interior() {
    // x ≥ −10 and y ≤ 10 do not bind: the optimum is the unconstrained one.
    let bounds = Bounds::new(vec![-10.0, f64::NEG_INFINITY], vec![f64::INFINITY, 10.0]).unwrap();
    let out = tight()
        .with_bounds(bounds)
        .minimize(rosenbrock, [-1.2, 1.0])
        .unwrap();
    assert!(out.converged());
    assert_near(&out, &[1.0, 1.0], 1e-6, 0.0, 1e-12);
}

#[test]
fn nan_region_is_avoided() {
    let nan_calls = Cell::new(0);
    let objective = |x: &[f64]| {
        let v = log_valley(x);
        if v.is_nan() {
            nan_calls.set(nan_calls.get() + 1);
        }
        v
    };
    // One initial vertex lies in the NaN region (x0 < 0).
    let simplex = vec![vec![1.0, 1.0], vec![-0.5, 1.0], vec![1.0, 2.0]];
    let out = tight()
        .minimize(objective, Start::Simplex(simplex))
        .unwrap();
    assert!(nan_calls.get() >= 1);
    assert!(out.converged());
    let e = std::f64::consts::E;
    assert_near(&out, &[e, e], 1e-7, 0.0, 1e-14);
    assert!(out.simplex_values.iter().all(|v| v.is_finite()));
    // NaN means exactly +inf: the same run with +inf in its place takes the same path.
    let simplex = vec![vec![1.0, 1.0], vec![-0.5, 1.0], vec![1.0, 2.0]];
    let with_inf = tight()
        .minimize(
            |x: &[f64]| {
                let v = log_valley(x);
                if v.is_nan() {
                    f64::INFINITY
                } else {
                    v
                }
            },
            Start::Simplex(simplex),
        )
        .unwrap();
    assert_eq!(out, with_inf);

    // A NaN half-plane x0 + x1 > 2.5 cuts off the unconstrained minimum (1, 2) of a
    // quadratic: the run stays out of it and ends on its edge, at the projection
    // (0.75, 1.75) with value 0.125, not at a NaN.
    let half_plane = |x: &[f64]| {
        if x[0] + x[1] > 2.5 {
            f64::NAN
        } else {
            (x[0] - 1.0).powi(2) + (x[1] - 2.0).powi(2)
        }
    };
    let out = tight().minimize(half_plane, [0.0, 0.0]).unwrap();
    assert!(out.f.is_finite() && out.x[0] + out.x[1] <= 2.5);
    assert_near(&out, &[0.75, 1.75], 1e-4, 0.125, 1e-8);
}

// ---- errors, limits, validation ----

#[test]
fn objective_error_aborts_the_run_with_that_error() {
    #[derive(Debug, PartialEq)]
    struct Broken(usize);
    impl std::fmt::Display for Broken {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "broken at call {}", self.0)
        }
    }
    let mut calls = 0;
    let result = tight().try_minimize(
        |x: &[f64]| {
            calls += 1;
            if calls == 17 {
                Err(Broken(calls))
            } else {
                Ok(rosenbrock(x))
            }
        },
        [-1.2, 1.0],
    );
    match result {
        Err(Error::Objective(e)) => assert_eq!(e, Broken(17)),
        other => panic!("expected the objective's error, got {other:?}"),
    }
    assert_eq!(calls, 17, "no call after the error");

    // The error displays with its cause; anyhow errors (not std::error::Error) work too.
    let err = tight()
        .try_minimize(
            |_: &[f64]| Err(anyhow::anyhow!("sensor log unreadable")),
            [1.0],
        )
        .unwrap_err();
    assert_eq!(err.to_string(), "objective failed: sensor log unreadable");

    // A fallible objective that never fails gives the same result as the plain one.
    let ok = tight()
        .try_minimize(|x: &[f64]| Ok::<_, Broken>(rosenbrock(x)), [-1.2, 1.0])
        .unwrap();
    assert_eq!(ok, tight().minimize(rosenbrock, [-1.2, 1.0]).unwrap());
}

#[test]
fn limits_stop_the_run_and_are_never_exceeded() {
    let calls = Cell::new(0);
    let counted = |x: &[f64]| {
        calls.set(calls.get() + 1);
        rosenbrock(x)
    };
    for max in [3, 4, 5, 50, 99, 100, 101] {
        calls.set(0);
        let out = tight()
            .with_max_evaluations(max)
            .unwrap()
            .minimize(counted, [-1.2, 1.0])
            .unwrap();
        assert_eq!(out.termination, Termination::MaxEvaluations, "max {max}");
        assert_eq!(out.evaluations, max);
        assert_eq!(calls.get(), max);
        // Reported value is the best ever evaluated.
        assert!(out.f <= out.simplex_values[0]);
        assert_eq!(rosenbrock(&out.x), out.f);
    }

    let out = tight()
        .with_max_iterations(25)
        .unwrap()
        .minimize(rosenbrock, [-1.2, 1.0])
        .unwrap();
    assert_eq!(out.termination, Termination::MaxIterations);
    assert_eq!(out.iterations, 25);
    assert_eq!(out.steps.total(), 25);

    // scipy's defaults: 200·n of each when neither is set (10-D Rosenbrock needs more).
    let out = NelderMead::new()
        .with_x_tolerance(1e-10)
        .unwrap()
        .with_f_tolerance(1e-10)
        .unwrap()
        .minimize(rosenbrock, [-1.0; 10])
        .unwrap();
    assert_eq!(out.termination, Termination::MaxEvaluations);
    assert_eq!(out.evaluations, 2000);
    assert_eq!(NelderMead::new().limits_for(3), (600, 600));
    let only_evals = NelderMead::new().with_max_evaluations(7).unwrap();
    assert_eq!(only_evals.limits_for(3), (usize::MAX, 7));
}

#[test]
fn default_tolerances_are_scipys_and_loose_ones_stop_early() {
    let default = NelderMead::new();
    assert_eq!(default.x_tolerance(), 1e-4);
    assert_eq!(default.f_tolerance(), 1e-4);
    let loose = NelderMead::new().minimize(rosenbrock, [-1.2, 1.0]).unwrap();
    let strict = tight().minimize(rosenbrock, [-1.2, 1.0]).unwrap();
    assert!(loose.converged() && loose.evaluations < strict.evaluations);
    assert_near(&loose, &[1.0, 1.0], 1e-3, 0.0, 1e-6);
    // An infinite tolerance switches its criterion off: only f decides here.
    let f_only = NelderMead::new()
        .with_x_tolerance(f64::INFINITY)
        .unwrap()
        .with_f_tolerance(1e-3)
        .unwrap()
        .minimize(rosenbrock, [-1.2, 1.0])
        .unwrap();
    let spread = f_only.simplex_values.last().unwrap() - f_only.simplex_values[0];
    assert!(f_only.converged() && spread <= 1e-3);
}

#[test]
fn settings_are_validated() {
    use SettingsError as S;
    let nm = NelderMead::new;
    for bad in [0.0, -1e-9, f64::NAN, f64::NEG_INFINITY] {
        assert!(matches!(
            nm().with_x_tolerance(bad),
            Err(S::NotPositive {
                name: "x_tolerance",
                ..
            })
        ));
        assert!(matches!(
            nm().with_f_tolerance(bad),
            Err(S::NotPositive {
                name: "f_tolerance",
                ..
            })
        ));
    }
    assert_eq!(
        nm().with_max_iterations(0).unwrap_err(),
        S::Zero {
            name: "max_iterations"
        }
    );
    assert_eq!(
        nm().with_max_evaluations(0).unwrap_err(),
        S::Zero {
            name: "max_evaluations"
        }
    );

    assert_eq!(
        Coefficients::new(1.0, 2.0, 0.5, 0.5).unwrap(),
        Coefficients::STANDARD
    );
    assert!(matches!(
        Coefficients::new(0.0, 2.0, 0.5, 0.5),
        Err(S::NotPositive {
            name: "reflection",
            ..
        })
    ));
    assert!(matches!(
        Coefficients::new(1.0, 1.0, 0.5, 0.5),
        Err(S::OutOfRange {
            name: "expansion",
            ..
        })
    ));
    assert!(matches!(
        Coefficients::new(2.5, 2.0, 0.5, 0.5),
        Err(S::ExpansionNotAboveReflection { .. })
    ));
    for c in [0.0, 1.0, -0.5, 1.5] {
        assert!(matches!(
            Coefficients::new(1.0, 2.0, c, 0.5),
            Err(S::OutOfRange {
                name: "contraction",
                ..
            })
        ));
        assert!(matches!(
            Coefficients::new(1.0, 2.0, 0.5, c),
            Err(S::OutOfRange { name: "shrink", .. })
        ));
    }
    assert!(matches!(
        Coefficients::new(f64::NAN, 2.0, 0.5, 0.5),
        Err(S::NonFinite {
            name: "reflection",
            ..
        })
    ));

    // Gao & Han: the standard set at n = 2 (and for n = 1, where their σ would be 0).
    assert_eq!(Coefficients::adaptive(2), Coefficients::STANDARD);
    assert_eq!(Coefficients::adaptive(1), Coefficients::STANDARD);
    let a = Coefficients::adaptive(10);
    assert_eq!(
        (a.reflection(), a.expansion(), a.contraction(), a.shrink()),
        (1.0, 1.2, 0.7, 0.9)
    );

    assert!(matches!(
        nm().with_initial_steps(InitialSteps::Absolute(vec![0.1, 0.0])),
        Err(S::Zero { .. })
    ));
    assert!(matches!(
        nm().with_initial_steps(InitialSteps::Relative {
            fraction: f64::INFINITY,
            zero_step: 0.1
        }),
        Err(S::NonFinite { .. })
    ));

    let inf = f64::INFINITY;
    assert!(matches!(
        Bounds::new(vec![0.0], vec![1.0, 2.0]),
        Err(S::BoundsLength { lower: 1, upper: 2 })
    ));
    for (lo, hi) in [
        (1.0, 1.0),
        (2.0, 1.0),
        (f64::NAN, 1.0),
        (inf, inf),
        (-f64::MAX, f64::MAX),
    ] {
        assert!(
            matches!(
                Bounds::new(vec![0.0, lo], vec![1.0, hi]),
                Err(S::BadBounds { index: 1, .. })
            ),
            "[{lo}, {hi}]"
        );
    }
}

#[test]
fn malformed_problems_are_rejected() {
    let f = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>();
    let nm = NelderMead::new();
    assert_eq!(nm.minimize(f, Vec::new()), Err(ProblemError::EmptyStart));
    assert!(matches!(
        nm.minimize(f, [1.0, f64::NAN]),
        Err(ProblemError::NonFinite {
            vertex: 0,
            index: 1,
            ..
        })
    ));
    // The 5 % step of 1e308 overflows.
    assert!(matches!(
        nm.minimize(f, [f64::MAX]),
        Err(ProblemError::NonFinite {
            vertex: 1,
            index: 0,
            ..
        })
    ));
    let bounded = nm
        .clone()
        .with_bounds(Bounds::new(vec![0.0; 2], vec![1.0; 2]).unwrap());
    assert!(matches!(
        bounded.minimize(f, [0.5, 1.5]),
        Err(ProblemError::OutsideBounds {
            vertex: 0,
            index: 1,
            ..
        })
    ));
    assert!(matches!(
        bounded.minimize(f, [0.5, 0.5, 0.5]),
        Err(ProblemError::DimensionMismatch {
            what: "bounds",
            expected: 3,
            found: 2
        })
    ));
    assert!(matches!(
        nm.clone()
            .with_initial_steps(InitialSteps::Absolute(vec![0.1]))
            .unwrap()
            .minimize(f, [1.0, 1.0]),
        Err(ProblemError::DimensionMismatch {
            what: "initial steps",
            ..
        })
    ));
    let simplex = |v: &[&[f64]]| Start::Simplex(v.iter().map(|r| r.to_vec()).collect());
    assert!(matches!(
        nm.minimize(f, simplex(&[&[0.0, 0.0], &[1.0, 0.0]])),
        Err(ProblemError::VertexCount {
            dimension: 2,
            found: 2
        })
    ));
    assert!(matches!(
        nm.minimize(f, simplex(&[&[0.0, 0.0], &[1.0, 0.0], &[1.0]])),
        Err(ProblemError::DimensionMismatch {
            what: "simplex vertex",
            ..
        })
    ));
    // Three collinear points do not span the plane.
    assert_eq!(
        nm.minimize(f, simplex(&[&[0.0, 0.0], &[1.0, 1.0], &[2.0, 2.0]])),
        Err(ProblemError::DegenerateSimplex { dimension: 2 })
    );
    // Badly scaled but genuine: accepted.
    let scaled = nm.minimize(f, simplex(&[&[0.0, 0.0], &[1e6, 0.0], &[0.0, 1e-6]]));
    assert!(scaled.is_ok());
    assert_eq!(
        nm.clone()
            .with_max_evaluations(2)
            .unwrap()
            .minimize(f, [1.0, 1.0]),
        Err(ProblemError::BudgetTooSmall { max: 2, needed: 3 })
    );
    assert_eq!(
        nm.minimize(|_: &[f64]| f64::NAN, [1.0, 1.0]),
        Err(ProblemError::NoFiniteValue)
    );
}

// ---- Lagarias et al.'s ordering rules ----

#[test]
fn accepted_point_goes_after_vertices_with_equal_value() {
    // Values 0, 1, 5 at the vertices; the reflection (1, −1) also scores 0, ties with the best
    // and is accepted (f_1 ≤ f_r < f_n). Lagarias: it goes after the old best.
    let f = |x: &[f64]| {
        if x[1] > 0.5 {
            5.0
        } else if x[0] > 0.5 && x[1] > -0.5 {
            1.0
        } else {
            0.0
        }
    };
    let start = Start::Simplex(vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![0.0, 1.0]]);
    let out = NelderMead::new()
        .with_max_iterations(1)
        .unwrap()
        .minimize(f, start)
        .unwrap();
    assert_eq!(out.steps.reflect, 1);
    assert_eq!(out.evaluations, 4);
    assert_eq!(
        out.simplex,
        vec![vec![0.0, 0.0], vec![1.0, -1.0], vec![1.0, 0.0]]
    );
    assert_eq!(out.simplex_values, vec![0.0, 0.0, 1.0]);
    assert_eq!(out.x, vec![0.0, 0.0]);
}

/// An objective defined by a table of exact points (trial points here are exact in binary).
fn table(points: &'static [(&'static [f64], f64)], default: f64) -> impl Fn(&[f64]) -> f64 {
    move |x: &[f64]| {
        points
            .iter()
            .find(|(p, _)| *p == x)
            .map_or(default, |&(_, v)| v)
    }
}

fn one_step(f: impl Fn(&[f64]) -> f64, simplex: &[&[f64]]) -> Outcome {
    let start = Start::Simplex(simplex.iter().map(|v| v.to_vec()).collect());
    NelderMead::new()
        .with_max_iterations(1)
        .unwrap()
        .minimize(f, start)
        .unwrap()
}

#[test]
fn acceptance_rules_at_equality_follow_lagarias() {
    // 1-D simplex {0, 1}: centroid 0, worst 1; trial points x_r = −1, x_e = −2, x_c = −0.5,
    // x_cc = 0.5.
    let line: &[&[f64]] = &[&[0.0], &[1.0]];

    // Expansion only if f_e < f_r: a tie keeps the reflected point.
    let out = one_step(
        table(&[(&[0.0], 1.0), (&[-1.0], 0.0), (&[-2.0], 0.0)], 2.0),
        line,
    );
    assert_eq!(out.steps.reflect, 1);
    assert_eq!(out.simplex, vec![vec![-1.0], vec![0.0]]);

    // Outside contraction accepted if f_c ≤ f_r: a tie is accepted.
    let out = one_step(
        table(&[(&[0.0], 0.0), (&[1.0], 10.0), (&[-1.0], 5.0)], 5.0),
        line,
    );
    assert_eq!(out.steps.contract_outside, 1, "{:?}", out.steps);
    assert_eq!(out.simplex, vec![vec![0.0], vec![-0.5]]);

    // Inside contraction accepted only if f_cc < f_worst: a tie shrinks.
    let out = one_step(table(&[(&[0.0], 0.0), (&[-1.0], 7.0)], 5.0), line);
    assert_eq!(out.steps.shrink, 1, "{:?}", out.steps);
    assert_eq!(out.evaluations, 2 + 2 + 1);

    // Reflection accepted only if f_r < f_n: a tie with the second worst contracts instead.
    // Simplex (0,0), (1,0), (0,1): centroid (0.5, 0), x_r = (1, −1), x_c = (0.75, −0.5).
    let out = one_step(
        table(
            &[
                (&[0.0, 0.0], 0.0),
                (&[1.0, 0.0], 1.0),
                (&[0.0, 1.0], 2.0),
                (&[1.0, -1.0], 1.0),
                (&[0.75, -0.5], 0.5),
            ],
            9.0,
        ),
        &[&[0.0, 0.0], &[1.0, 0.0], &[0.0, 1.0]],
    );
    assert_eq!(out.steps.contract_outside, 1, "{:?}", out.steps);
    assert_eq!(out.simplex[1], vec![0.75, -0.5]);
}

#[test]
fn shrink_keeps_the_old_best_first_among_ties() {
    // On a constant function every step fails and shrinks towards vertex 0, which must stay
    // the best vertex throughout (Lagarias' shrink tie rule): the run ends exactly at the start.
    let out = NelderMead::new()
        .with_x_tolerance(1e-6)
        .unwrap()
        .minimize(|_: &[f64]| 4.0, [0.3, -0.7, 2.0])
        .unwrap();
    assert!(out.converged());
    assert_eq!(out.steps.shrink, out.iterations);
    assert!(out.iterations > 5);
    assert_eq!(out.x, vec![0.3, -0.7, 2.0]);
    assert_eq!(out.simplex[0], vec![0.3, -0.7, 2.0]);
}

#[test]
fn initial_simplex_follows_scipys_rule() {
    // One iteration-free run (a huge tolerance) reports the initial simplex.
    let out = NelderMead::new()
        .with_x_tolerance(f64::INFINITY)
        .unwrap()
        .with_f_tolerance(f64::INFINITY)
        .unwrap()
        .minimize(|_: &[f64]| 1.0, [2.0, 0.0])
        .unwrap();
    assert_eq!(out.iterations, 0);
    assert_eq!(out.evaluations, 3);
    assert_eq!(
        out.simplex,
        vec![vec![2.0, 0.0], vec![1.05 * 2.0, 0.0], vec![2.0, 0.00025]]
    );
}
