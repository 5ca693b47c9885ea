//! Nelder-Mead simplex minimisation, derivative-free, with box bounds.
//!
//! The method is Nelder & Mead's with the precise rules of Lagarias, Reeds, Wright & Wright,
//! "Convergence properties of the Nelder-Mead simplex method in low dimensions" (SIAM J.
//! Optim. 9(1), 1998). Each iteration, with vertices ordered `f_1 ≤ … ≤ f_{n+1}`, centroid
//! `c` of the best n and the trial points of [`Coefficients`]:
//!
//! 1. reflect: `f_r = f(x_r)`; if `f_1 ≤ f_r < f_n` accept `x_r`;
//! 2. if `f_r < f_1` expand: accept `x_e` if `f_e < f_r`, else `x_r`;
//! 3. if `f_n ≤ f_r < f_{n+1}` contract outside: accept `x_c` if `f_c ≤ f_r`, else shrink;
//! 4. if `f_r ≥ f_{n+1}` contract inside: accept `x_cc` if `f_cc < f_{n+1}`, else shrink;
//! 5. shrink: every vertex but the best moves halfway (σ) towards it; n evaluations.
//!
//! Ordering ties follow Lagarias et al.: an accepted point is inserted *after* all vertices with
//! the same value, and after a shrink the old best vertex stays first among equal values.
//! This is also what `scipy.optimize.minimize(method='Nelder-Mead')` does; trial points are
//! computed with scipy's formulas, so on an unbounded problem from the same simplex both take
//! the same path (`tests/nelder_mead.rs` checks this against scipy's output).
//!
//! - **Initial simplex**: from a start point by [`InitialSteps`] (scipy's rule by default: 5 %
//!   of each non-zero coordinate, 0.00025 for a zero one), or given vertex by vertex
//!   ([`Start::Simplex`]).
//! - **Bounds** by a change of variables ([`Bounds`]): the objective only ever sees feasible
//!   points; results are in the original coordinates.
//! - **Termination** (checked before every iteration, in this order): converged when
//!   `max |x_i − x_best| ≤ x_tolerance` (every coordinate of every vertex) *and*
//!   `max |f_i − f_best| ≤ f_tolerance` (scipy's `xatol`/`fatol`); the evaluation limit (never
//!   exceeded — a step that would need one more call stops the run); the iteration limit.
//! - **Objective values**: NaN counts as +∞ (the simplex moves away from it); an `Err` from a
//!   fallible objective ([`NelderMead::try_minimize`]) aborts the run with that error.
//!
//! ```
//! use nelder_mead::{NelderMead, Termination};
//! let rosenbrock = |x: &[f64]| 100.0 * (x[1] - x[0] * x[0]).powi(2) + (1.0 - x[0]).powi(2);
//! let outcome = NelderMead::new()
//!     .with_x_tolerance(1e-8)?
//!     .with_f_tolerance(1e-10)?
//!     .with_max_evaluations(1000)?
//!     .minimize(rosenbrock, [-1.2, 1.0])?;
//! assert_eq!(outcome.termination, Termination::Converged);
//! assert!((outcome.x[0] - 1.0).abs() < 1e-6 && (outcome.x[1] - 1.0).abs() < 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod bounds;
mod settings;

pub use bounds::Bounds;
use bounds::Map;
pub use settings::{CoefficientRule, Coefficients, InitialSteps, NelderMead, SettingsError};
use std::convert::Infallible;

/// Where a run starts.
#[derive(Clone, Debug, PartialEq)]
pub enum Start {
    /// A start point; the other n vertices follow from [`InitialSteps`].
    Point(Vec<f64>),
    /// All n + 1 vertices, each with n coordinates (scipy's `initial_simplex`).
    Simplex(Vec<Vec<f64>>),
}

impl From<Vec<f64>> for Start {
    fn from(x0: Vec<f64>) -> Self {
        Self::Point(x0)
    }
}

impl From<&Vec<f64>> for Start {
    fn from(x0: &Vec<f64>) -> Self {
        Self::Point(x0.clone())
    }
}

impl From<&[f64]> for Start {
    fn from(x0: &[f64]) -> Self {
        Self::Point(x0.to_vec())
    }
}

impl<const N: usize> From<[f64; N]> for Start {
    fn from(x0: [f64; N]) -> Self {
        Self::Point(x0.to_vec())
    }
}

impl<const N: usize> From<&[f64; N]> for Start {
    fn from(x0: &[f64; N]) -> Self {
        Self::Point(x0.to_vec())
    }
}

/// Why a run could not start (the problem does not fit the settings, or is malformed).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProblemError {
    /// The start point has no coordinates.
    #[error("the start point has no coordinates")]
    EmptyStart,
    /// Something has the wrong number of coordinates.
    #[error("{what} has {found} coordinates, the start has {expected}")]
    DimensionMismatch {
        /// What ("bounds", "initial steps", "simplex vertex").
        what: &'static str,
        /// The start's dimension.
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// A user simplex does not have n + 1 vertices.
    #[error("a simplex in {dimension} dimensions needs {} vertices, got {found}", dimension + 1)]
    VertexCount {
        /// Dimension (length of the first vertex).
        dimension: usize,
        /// Vertices given.
        found: usize,
    },
    /// A vertex coordinate is NaN or infinite (given, or overflowed while building the simplex).
    #[error("vertex {vertex}: x[{index}] = {value} is not finite")]
    NonFinite {
        /// Vertex (0 is the start point).
        vertex: usize,
        /// Coordinate.
        index: usize,
        /// Value.
        value: f64,
    },
    /// A given point lies outside the bounds.
    #[error("vertex {vertex}: x[{index}] = {value} is outside the bounds [{lower}, {upper}]")]
    OutsideBounds {
        /// Vertex (0 is the start point).
        vertex: usize,
        /// Coordinate.
        index: usize,
        /// Value.
        value: f64,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// The initial simplex does not span the space (its vertices are affinely dependent,
    /// numerically), so Nelder-Mead could never leave a subspace.
    #[error("the initial simplex is degenerate: its vertices do not span {dimension} dimensions")]
    DegenerateSimplex {
        /// Dimension.
        dimension: usize,
    },
    /// The evaluation limit is below what the initial simplex needs.
    #[error("max_evaluations = {max} is below the {needed} evaluations of the initial simplex")]
    BudgetTooSmall {
        /// Evaluation limit in effect.
        max: usize,
        /// n + 1.
        needed: usize,
    },
    /// The objective is NaN or +∞ at every vertex of the initial simplex.
    #[error("the objective is NaN or +inf at every vertex of the initial simplex")]
    NoFiniteValue,
}

/// Why a run with a fallible objective failed.
#[derive(Debug, thiserror::Error)]
pub enum Error<E> {
    /// The run could not start.
    #[error(transparent)]
    Problem(#[from] ProblemError),
    /// The objective returned this error; the run was aborted.
    #[error("objective failed: {0}")]
    Objective(E),
}

/// Why a run stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Termination {
    /// Both the x and the f tolerance were met.
    Converged,
    /// The iteration limit was reached.
    MaxIterations,
    /// The evaluation limit was reached (possibly in the middle of a step).
    MaxEvaluations,
}

/// What kind of step each iteration ended with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct StepCounts {
    /// Reflected point accepted (including after an expansion that did not improve on it).
    pub reflect: usize,
    /// Expanded point accepted.
    pub expand: usize,
    /// Outside contraction accepted.
    pub contract_outside: usize,
    /// Inside contraction accepted.
    pub contract_inside: usize,
    /// Shrinks.
    pub shrink: usize,
}

impl StepCounts {
    /// All steps: equals the number of iterations.
    pub fn total(&self) -> usize {
        self.reflect + self.expand + self.contract_outside + self.contract_inside + self.shrink
    }

    /// Count one step of `kind`.
    fn count(&mut self, kind: Kind) {
        match kind {
            Kind::Reflect => self.reflect += 1,
            Kind::Expand => self.expand += 1,
            Kind::ContractOutside => self.contract_outside += 1,
            Kind::ContractInside => self.contract_inside += 1,
            Kind::Shrink => self.shrink += 1,
        }
    }
}

/// The result of a run, in the original coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// The best point evaluated. Normally the best vertex of `simplex`; if the evaluation
    /// limit cut a step short, possibly that step's trial point.
    pub x: Vec<f64>,
    /// The objective at `x` (NaN reported as +∞).
    pub f: f64,
    /// Completed iterations (scipy's `nit` is one more: it counts from 1).
    pub iterations: usize,
    /// Objective calls, including the n + 1 on the initial simplex.
    pub evaluations: usize,
    /// Why the run stopped.
    pub termination: Termination,
    /// Kinds of the completed iterations.
    pub steps: StepCounts,
    /// The final simplex, best vertex first.
    pub simplex: Vec<Vec<f64>>,
    /// Objective values of `simplex`, ascending.
    pub simplex_values: Vec<f64>,
}

impl Outcome {
    /// True if the run met its tolerances.
    pub fn converged(&self) -> bool {
        self.termination == Termination::Converged
    }
}

impl NelderMead {
    /// Minimise `objective` from `start` (a point — `[f64; N]`, `&[f64]`, `Vec<f64>` — or a
    /// [`Start::Simplex`]); the dimension is the start's.
    ///
    /// ```
    /// use nelder_mead::{Bounds, NelderMead};
    /// // (x − 3)² is smallest at 3, but x must stay in [−1, 2]: the answer is the bound.
    /// let settings = NelderMead::new()
    ///     .with_bounds(Bounds::new(vec![-1.0], vec![2.0])?)
    ///     .with_x_tolerance(1e-9)?
    ///     .with_f_tolerance(1e-12)?;
    /// let outcome = settings.minimize(|x| (x[0] - 3.0).powi(2), [0.5])?;
    /// assert!(outcome.converged());
    /// assert!((outcome.x[0] - 2.0).abs() < 1e-6 && outcome.x[0] <= 2.0);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn minimize<F>(
        &self,
        mut objective: F,
        start: impl Into<Start>,
    ) -> Result<Outcome, ProblemError>
    where
        F: FnMut(&[f64]) -> f64,
    {
        match self.try_minimize(|x| Ok::<f64, Infallible>(objective(x)), start) {
            Ok(outcome) => Ok(outcome),
            Err(Error::Problem(e)) => Err(e),
            Err(Error::Objective(never)) => match never {},
        }
    }

    /// [`minimize`](Self::minimize) with a fallible objective: the first `Err` aborts the run
    /// and is returned as [`Error::Objective`].
    pub fn try_minimize<E, F>(
        &self,
        mut objective: F,
        start: impl Into<Start>,
    ) -> Result<Outcome, Error<E>>
    where
        F: FnMut(&[f64]) -> Result<f64, E>,
    {
        let vertices = self.initial_vertices(start.into())?;
        let n = vertices.len() - 1;
        let maps = match &self.bounds {
            Some(b) => b.maps(),
            None => vec![Map::Free; n],
        };
        let (max_iterations, max_evaluations) = self.limits_for(n);
        if max_evaluations < n + 1 {
            return Err(ProblemError::BudgetTooSmall {
                max: max_evaluations,
                needed: n + 1,
            }
            .into());
        }
        let coefficients = self.coefficients.for_dimension(n);

        let mut st = State {
            n,
            u: vertices
                .iter()
                .flat_map(|v| v.iter().zip(&maps).map(|(&x, m)| m.to_inner(x)))
                .collect(),
            x: vec![0.0; (n + 1) * n],
            f: vec![f64::INFINITY; n + 1],
            order: (0..=n).collect(),
        };
        if is_degenerate(&st.u, n) {
            return Err(ProblemError::DegenerateSimplex { dimension: n }.into());
        }

        let mut ev = Evaluator {
            objective: &mut objective,
            maps: &maps,
            used: 0,
            max: max_evaluations,
            best_f: f64::INFINITY,
            best_x: vertices[0].clone(),
        };
        evaluate_initial(&mut st, &mut ev)?;
        let (termination, iterations, steps) = self
            .iterate(&mut st, &coefficients, &mut ev, max_iterations)
            .map_err(Error::Objective)?;
        st.sort();

        Ok(Outcome {
            x: ev.best_x,
            f: ev.best_f,
            iterations,
            evaluations: ev.used,
            termination,
            steps,
            simplex: st.order.iter().map(|&j| st.x_row(j).to_vec()).collect(),
            simplex_values: st.order.iter().map(|&j| st.f[j]).collect(),
        })
    }

    /// Iterate on the evaluated simplex `st` until it converges or the iteration or
    /// evaluation limit is reached: why it stopped, the iterations completed and their kinds.
    fn iterate<E, F>(
        &self,
        st: &mut State,
        coefficients: &Coefficients,
        ev: &mut Evaluator<'_, F>,
        max_iterations: usize,
    ) -> Result<(Termination, usize, StepCounts), E>
    where
        F: FnMut(&[f64]) -> Result<f64, E>,
    {
        let mut work = Work::new(st.n);
        let mut iterations = 0;
        let mut steps = StepCounts::default();
        let termination = loop {
            if st.converged(self.x_tolerance, self.f_tolerance) {
                break Termination::Converged;
            }
            if ev.used >= ev.max {
                break Termination::MaxEvaluations;
            }
            if iterations >= max_iterations {
                break Termination::MaxIterations;
            }
            match st.step(coefficients, &mut work, ev)? {
                Some(kind) => {
                    iterations += 1;
                    steps.count(kind);
                }
                None => break Termination::MaxEvaluations,
            }
        };
        Ok((termination, iterations, steps))
    }

    /// The n + 1 vertices in the original space, checked against the settings.
    fn initial_vertices(&self, start: Start) -> Result<Vec<Vec<f64>>, ProblemError> {
        let vertices = match start {
            Start::Point(x0) => {
                let n = x0.len();
                if n == 0 {
                    return Err(ProblemError::EmptyStart);
                }
                self.check_vertex(0, &x0, n)?;
                if let InitialSteps::Absolute(s) = &self.initial_steps {
                    if s.len() != n {
                        return Err(ProblemError::DimensionMismatch {
                            what: "initial steps",
                            expected: n,
                            found: s.len(),
                        });
                    }
                }
                let mut vertices = Vec::with_capacity(n + 1);
                vertices.push(x0.clone());
                for k in 0..n {
                    let mut y = x0.clone();
                    y[k] = match &self.initial_steps {
                        InitialSteps::Relative {
                            fraction,
                            zero_step,
                        } => {
                            if y[k] != 0.0 {
                                (1.0 + fraction) * y[k]
                            } else {
                                *zero_step
                            }
                        }
                        InitialSteps::Absolute(s) => y[k] + s[k],
                    };
                    if let Some(b) = &self.bounds {
                        // Like scipy: a step past a bound is reflected back into the box.
                        let (lo, hi) = (b.lower()[k], b.upper()[k]);
                        if y[k] > hi {
                            y[k] = 2.0 * hi - y[k];
                        } else if y[k] < lo {
                            y[k] = 2.0 * lo - y[k];
                        }
                        y[k] = y[k].clamp(lo, hi);
                    }
                    self.check_vertex(k + 1, &y, n)?;
                    vertices.push(y);
                }
                vertices
            }
            Start::Simplex(vertices) => {
                let n = vertices.first().map_or(0, Vec::len);
                if n == 0 {
                    return Err(ProblemError::EmptyStart);
                }
                if vertices.len() != n + 1 {
                    return Err(ProblemError::VertexCount {
                        dimension: n,
                        found: vertices.len(),
                    });
                }
                for (j, v) in vertices.iter().enumerate() {
                    self.check_vertex(j, v, n)?;
                }
                vertices
            }
        };
        Ok(vertices)
    }

    fn check_vertex(&self, vertex: usize, v: &[f64], n: usize) -> Result<(), ProblemError> {
        if v.len() != n {
            return Err(ProblemError::DimensionMismatch {
                what: "simplex vertex",
                expected: n,
                found: v.len(),
            });
        }
        if let Some((index, &value)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
            return Err(ProblemError::NonFinite {
                vertex,
                index,
                value,
            });
        }
        if let Some(b) = &self.bounds {
            if b.len() != n {
                return Err(ProblemError::DimensionMismatch {
                    what: "bounds",
                    expected: n,
                    found: b.len(),
                });
            }
            for (index, &value) in v.iter().enumerate() {
                let (lower, upper) = (b.lower()[index], b.upper()[index]);
                if !(lower <= value && value <= upper) {
                    return Err(ProblemError::OutsideBounds {
                        vertex,
                        index,
                        value,
                        lower,
                        upper,
                    });
                }
            }
        }
        Ok(())
    }
}

/// Evaluate the n + 1 vertices of the initial simplex `st` and sort them; an error if the
/// objective fails or is NaN or +∞ at every one.
fn evaluate_initial<E, F>(st: &mut State, ev: &mut Evaluator<'_, F>) -> Result<(), Error<E>>
where
    F: FnMut(&[f64]) -> Result<f64, E>,
{
    let n = st.n;
    for j in 0..=n {
        let rows = j * n..(j + 1) * n;
        // The budget check above guarantees these n + 1 calls.
        if let Some(v) = ev
            .call(&st.u[rows.clone()], &mut st.x[rows])
            .map_err(Error::Objective)?
        {
            st.f[j] = v;
        }
    }
    if st.f.iter().all(|&v| v == f64::INFINITY) {
        return Err(ProblemError::NoFiniteValue.into());
    }
    st.sort();
    Ok(())
}

/// Counts and performs objective calls; remembers the best point seen.
struct Evaluator<'a, F> {
    objective: &'a mut F,
    maps: &'a [Map],
    used: usize,
    max: usize,
    best_f: f64,
    best_x: Vec<f64>,
}

impl<F> Evaluator<'_, F> {
    /// Map `u` into `x` and evaluate there; `Ok(None)` if the budget is spent.
    fn call<E>(&mut self, u: &[f64], x: &mut [f64]) -> Result<Option<f64>, E>
    where
        F: FnMut(&[f64]) -> Result<f64, E>,
    {
        if self.used >= self.max {
            return Ok(None);
        }
        for ((xi, &ui), m) in x.iter_mut().zip(u).zip(self.maps) {
            *xi = m.to_outer(ui);
        }
        self.used += 1;
        let v = (self.objective)(x)?;
        let v = if v.is_nan() { f64::INFINITY } else { v };
        if v < self.best_f {
            self.best_f = v;
            self.best_x.copy_from_slice(x);
        }
        Ok(Some(v))
    }
}

/// The simplex: unconstrained coordinates `u`, original coordinates `x` (rows of n), values,
/// and the order of the rows (best first).
struct State {
    n: usize,
    u: Vec<f64>,
    x: Vec<f64>,
    f: Vec<f64>,
    order: Vec<usize>,
}

/// Scratch vectors, allocated once per run.
struct Work {
    centroid: Vec<f64>,
    r_u: Vec<f64>,
    r_x: Vec<f64>,
    t_u: Vec<f64>,
    t_x: Vec<f64>,
}

impl Work {
    fn new(n: usize) -> Self {
        Self {
            centroid: vec![0.0; n],
            r_u: vec![0.0; n],
            r_x: vec![0.0; n],
            t_u: vec![0.0; n],
            t_x: vec![0.0; n],
        }
    }
}

#[derive(Clone, Copy)]
enum Kind {
    Reflect,
    Expand,
    ContractOutside,
    ContractInside,
    Shrink,
}

impl State {
    fn u_row(&self, j: usize) -> &[f64] {
        &self.u[j * self.n..(j + 1) * self.n]
    }

    fn x_row(&self, j: usize) -> &[f64] {
        &self.x[j * self.n..(j + 1) * self.n]
    }

    /// Stable insertion sort of `order` by value: among equal values the earlier row order
    /// stays, so after a shrink the old best (first) remains first.
    fn sort(&mut self) {
        for i in 1..self.order.len() {
            let mut k = i;
            while k > 0 && self.f[self.order[k]] < self.f[self.order[k - 1]] {
                self.order.swap(k, k - 1);
                k -= 1;
            }
        }
    }

    fn converged(&self, x_tolerance: f64, f_tolerance: f64) -> bool {
        let best = self.order[0];
        let (x0, f0) = (self.x_row(best), self.f[best]);
        // Written as `d <= tol` so that a NaN difference (∞ − ∞) means "not converged".
        self.order[1..].iter().all(|&j| {
            (self.f[j] - f0).abs() <= f_tolerance
                && self
                    .x_row(j)
                    .iter()
                    .zip(x0)
                    .all(|(a, b)| (a - b).abs() <= x_tolerance)
        })
    }

    /// Replace the worst vertex by a point (Lagarias' ordering: after all equal values).
    fn accept(&mut self, u: &[f64], x: &[f64], value: f64) {
        let n = self.n;
        let worst = self.order[n];
        self.u[worst * n..(worst + 1) * n].copy_from_slice(u);
        self.x[worst * n..(worst + 1) * n].copy_from_slice(x);
        self.f[worst] = value;
        let k = (0..n).find(|&k| value < self.f[self.order[k]]).unwrap_or(n);
        self.order.copy_within(k..n, k + 1);
        self.order[k] = worst;
    }

    /// One Nelder-Mead iteration; `Ok(None)` if the evaluation budget ran out during it.
    fn step<E, F>(
        &mut self,
        c: &Coefficients,
        w: &mut Work,
        ev: &mut Evaluator<'_, F>,
    ) -> Result<Option<Kind>, E>
    where
        F: FnMut(&[f64]) -> Result<f64, E>,
    {
        let n = self.n;
        let (a, g, r, s) = (c.reflection(), c.expansion(), c.contraction(), c.shrink());
        let (best, worst) = (self.order[0], self.order[n]);
        let (f_best, f_next, f_worst) = (self.f[best], self.f[self.order[n - 1]], self.f[worst]);

        self.centroid_into(&mut w.centroid);
        let uw = &self.u[worst * n..(worst + 1) * n];

        // Trial points with scipy's exact expressions.
        let trial = |out: &mut [f64], p: f64, q: f64| {
            for ((o, &ci), &wi) in out.iter_mut().zip(&w.centroid).zip(uw) {
                *o = p * ci - q * wi;
            }
        };
        trial(&mut w.r_u, 1.0 + a, a);
        let Some(f_r) = ev.call(&w.r_u, &mut w.r_x)? else {
            return Ok(None);
        };

        if f_r < f_best {
            trial(&mut w.t_u, 1.0 + a * g, a * g);
            let Some(f_e) = ev.call(&w.t_u, &mut w.t_x)? else {
                return Ok(None);
            };
            if f_e < f_r {
                self.accept(&w.t_u, &w.t_x, f_e);
                return Ok(Some(Kind::Expand));
            }
            self.accept(&w.r_u, &w.r_x, f_r);
            return Ok(Some(Kind::Reflect));
        }
        if f_r < f_next {
            self.accept(&w.r_u, &w.r_x, f_r);
            return Ok(Some(Kind::Reflect));
        }
        if f_r < f_worst {
            trial(&mut w.t_u, 1.0 + r * a, r * a);
            let Some(f_c) = ev.call(&w.t_u, &mut w.t_x)? else {
                return Ok(None);
            };
            if f_c <= f_r {
                self.accept(&w.t_u, &w.t_x, f_c);
                return Ok(Some(Kind::ContractOutside));
            }
        } else {
            // Inside contraction: (1 − ρ)·c + ρ·x_w.
            trial(&mut w.t_u, 1.0 - r, -r);
            let Some(f_cc) = ev.call(&w.t_u, &mut w.t_x)? else {
                return Ok(None);
            };
            if f_cc < f_worst {
                self.accept(&w.t_u, &w.t_x, f_cc);
                return Ok(Some(Kind::ContractInside));
            }
        }
        self.shrink(s, w, ev)
    }

    /// The centroid of all vertices but the worst into `centroid`, summed in order as
    /// scipy does.
    fn centroid_into(&self, centroid: &mut [f64]) {
        let n = self.n;
        centroid.copy_from_slice(self.u_row(self.order[0]));
        for &j in &self.order[1..n] {
            for (ci, &ui) in centroid.iter_mut().zip(&self.u[j * n..(j + 1) * n]) {
                *ci += ui;
            }
        }
        let nf = n as f64;
        centroid.iter_mut().for_each(|ci| *ci /= nf);
    }

    /// Shrink every vertex towards the best by `s`; `Ok(None)` if the evaluation budget
    /// ran out during it.
    fn shrink<E, F>(
        &mut self,
        s: f64,
        w: &mut Work,
        ev: &mut Evaluator<'_, F>,
    ) -> Result<Option<Kind>, E>
    where
        F: FnMut(&[f64]) -> Result<f64, E>,
    {
        let n = self.n;
        let best = self.order[0];
        // Shrink towards the best vertex, in order; a vertex is only replaced once evaluated.
        for k in 1..=n {
            let j = self.order[k];
            for i in 0..n {
                let b = self.u[best * n + i];
                w.t_u[i] = b + s * (self.u[j * n + i] - b);
            }
            let Some(v) = ev.call(&w.t_u, &mut w.t_x)? else {
                return Ok(None);
            };
            self.u[j * n..(j + 1) * n].copy_from_slice(&w.t_u);
            self.x[j * n..(j + 1) * n].copy_from_slice(&w.t_x);
            self.f[j] = v;
        }
        self.sort();
        Ok(Some(Kind::Shrink))
    }
}

/// True if the rows `u_1 − u_0, …, u_n − u_0` are numerically linearly dependent: Gaussian
/// elimination with partial pivoting after scaling every coordinate to a largest difference of
/// 1 (so badly scaled but genuine simplices pass).
fn is_degenerate(u: &[f64], n: usize) -> bool {
    let mut m: Vec<f64> = (1..=n)
        .flat_map(|i| (0..n).map(move |j| u[i * n + j] - u[j]))
        .collect();
    for col in 0..n {
        let scale = (0..n).fold(0.0_f64, |acc, row| acc.max(m[row * n + col].abs()));
        if !(scale > 0.0 && scale.is_finite()) {
            return true;
        }
        (0..n).for_each(|row| m[row * n + col] /= scale);
    }
    let tol = n as f64 * f64::EPSILON;
    for col in 0..n {
        let (pivot_row, pivot) =
            (col..n)
                .map(|row| (row, m[row * n + col].abs()))
                .fold(
                    (col, -1.0),
                    |acc, cur| if cur.1 > acc.1 { cur } else { acc },
                );
        if pivot <= tol {
            return true;
        }
        for c in 0..n {
            m.swap(col * n + c, pivot_row * n + c);
        }
        for row in col + 1..n {
            let factor = m[row * n + col] / m[col * n + col];
            for c in col..n {
                m[row * n + c] -= factor * m[col * n + c];
            }
        }
    }
    false
}
