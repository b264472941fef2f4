//! Fixation point from the two gaze rays (seed 000, section 1): the midpoint of the rays' closest
//! approach, with a tested fallback where that point is ill-conditioned or meaningless, and an
//! exponential smoothing filter.
//!
//! "Depth" is measured along the cyclopean gaze: with unit gaze directions d1, d2, eye midpoint
//! m = (o1 + o2) / 2 and g = (d1 + d2) / |d1 + d2|, depth(F) = (F - m) . g.

use crate::error::{Error, Result};

/// Smallest `den = 1 - (d1 . d2)^2` solved in closed form; below it the rays count as parallel.
///
/// Rounding (u = 2^-53): b = d1 . d2 is off by <= ~5u, so den = 1 - b^2 is off by <= ~11u
/// absolutely, and the numerators b f - c, f - b c by <= ~12u |r|. The closest points, hence the
/// fixation, are off by about `12 u (|s| + |t| + |r|) / den` ([`ERROR_GAIN`]). Keeping that below
/// 1e-6 of the scale needs den >= 16u / 1e-6 ~ 1.8e-9; 1e-8 leaves a factor 5 (bound 1.8e-7). It
/// is reached at sin(vergence angle) = 1e-4: a 65 mm IPD verging at 650 m, beyond any depth range.
pub const MIN_DEN: f64 = 1e-8;

/// Constant K of the fixation error bound `K u (|s| + |t| + |r|) / den` (12 derived, rounded up).
pub const ERROR_GAIN: f64 = 16.0;

/// Gaze directions whose unit sum is shorter than this have no mean direction (eyes looking
/// in opposite directions) and are refused.
const MIN_GAZE_SUM: f64 = 1e-6;

/// One eye's gaze: origin (eye centre) and direction (any length > 0; normalised here).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GazeRay {
    /// The eye centre, world coordinates.
    pub origin: [f64; 3],
    /// Where the eye looks.
    pub direction: [f64; 3],
}

/// Accepted fixation depths, 0 < min < max, both finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthRange {
    min: f64,
    max: f64,
}

impl DepthRange {
    /// The range [min, max]; refused unless 0 < min < max, both finite.
    pub fn new(min: f64, max: f64) -> Result<Self> {
        if !(min.is_finite() && max.is_finite() && min > 0.0 && max > min) {
            return Err(Error::param(
                "fixation depth range",
                format!("[{min}, {max}] must be finite with 0 < min < max"),
            ));
        }
        Ok(DepthRange { min, max })
    }

    /// The nearest accepted depth.
    pub fn min(&self) -> f64 {
        self.min
    }

    /// The farthest accepted depth (also the last fallback).
    pub fn max(&self) -> f64 {
        self.max
    }
}

/// Why the closed form was not used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FallbackReason {
    /// Both eyes at the same point: the rays only meet there (or coincide), no vergence depth.
    ZeroBaseline,
    /// `den < MIN_DEN`.
    NearlyParallel {
        /// 1 - (d1 . d2)^2 of the unit gazes.
        den: f64,
    },
    /// A closest point lies at or behind its eye (`s <= 0` or `t <= 0`): diverging gaze.
    BehindEye {
        /// Distance along the left gaze.
        s: f64,
        /// Distance along the right gaze.
        t: f64,
    },
    /// The fixation's depth is outside the accepted range.
    OutOfRange {
        /// The depth found.
        depth: f64,
    },
}

/// Result of the closed form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fixation {
    /// Midpoint of the closest points o1 + s d1 and o2 + t d2 (s, t: distances along the unit
    /// gazes); `gap` is the distance between those points (0 for intersecting rays).
    Converged {
        /// The fixation point, world coordinates.
        point: [f64; 3],
        /// Distance along the left unit gaze.
        s: f64,
        /// Distance along the right unit gaze.
        t: f64,
        /// Depth of the point along the mean gaze.
        depth: f64,
        /// Distance between the two closest points.
        gap: f64,
    },
    /// The closed form does not apply; the caller falls back.
    Fallback {
        /// Why.
        reason: FallbackReason,
    },
}

/// Where a resolved fixation came from; fallbacks carry the closed form's reason.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FixationSource {
    /// The closed form: the gazes converge in range.
    Vergence,
    /// The depth under the gaze pixel, along the mean gaze.
    GazePixelDepth(FallbackReason),
    /// The previous frame's fixation.
    LastFixation(FallbackReason),
    /// The far end of the accepted range along the mean gaze.
    MaxDepth(FallbackReason),
}

/// A fixation point, its depth (in range) and the branch that produced it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResolvedFixation {
    /// The fixation point, world coordinates.
    pub point: [f64; 3],
    /// Its depth, within the accepted range.
    pub depth: f64,
    /// The branch that produced it.
    pub source: FixationSource,
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: [f64; 3], k: f64) -> [f64; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

fn finite(a: [f64; 3]) -> bool {
    a.iter().all(|v| v.is_finite())
}

/// Unit vector; pre-scaled by the largest component so tiny or huge inputs neither under- nor
/// overflow.
fn unit(name: &str, v: [f64; 3]) -> Result<[f64; 3]> {
    let big = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if !finite(v) || big == 0.0 {
        return Err(Error::param(name, format!("{v:?} must be finite and non-zero")));
    }
    let w = scale(v, 1.0 / big);
    Ok(scale(w, 1.0 / norm(w)))
}

/// Validated, normalised eye pair.
struct Rig {
    p: [f64; 3],
    q: [f64; 3],
    d1: [f64; 3],
    d2: [f64; 3],
    /// Eye midpoint and unit mean gaze.
    m: [f64; 3],
    g: [f64; 3],
}

impl Rig {
    fn new(left: &GazeRay, right: &GazeRay) -> Result<Rig> {
        let d1 = unit("left gaze direction", left.direction)?;
        let d2 = unit("right gaze direction", right.direction)?;
        let (p, q) = (left.origin, right.origin);
        let m = scale(add(p, q), 0.5);
        if !finite(m) || !finite(sub(p, q)) {
            return Err(Error::param(
                "gaze origins",
                format!("{p:?}, {q:?} must be finite (and < 1e307)"),
            ));
        }
        let sum = add(d1, d2);
        let len = norm(sum);
        if len < MIN_GAZE_SUM {
            return Err(Error::param("gaze directions", "opposite: no mean gaze direction"));
        }
        Ok(Rig {
            p,
            q,
            d1,
            d2,
            m,
            g: scale(sum, 1.0 / len),
        })
    }

    /// Seed 000's closed form with the documented fallback conditions, checked in this order.
    fn solve(&self, range: &DepthRange) -> Result<Fixation> {
        let fallback = |reason| Ok(Fixation::Fallback { reason });
        let r = sub(self.p, self.q);
        if r == [0.0; 3] {
            return fallback(FallbackReason::ZeroBaseline);
        }
        let b = dot(self.d1, self.d2);
        let c = dot(self.d1, r);
        let f = dot(self.d2, r);
        let den = 1.0 - b * b;
        if den < MIN_DEN {
            return fallback(FallbackReason::NearlyParallel { den });
        }
        let s = (b * f - c) / den;
        let t = (f - b * c) / den;
        if s <= 0.0 || t <= 0.0 {
            return fallback(FallbackReason::BehindEye { s, t });
        }
        let pp = add(self.p, scale(self.d1, s));
        let qq = add(self.q, scale(self.d2, t));
        let point = scale(add(pp, qq), 0.5);
        let depth = dot(sub(point, self.m), self.g);
        if !finite(point) || !depth.is_finite() {
            return Err(Error::param("gaze origins", "fixation overflows f64"));
        }
        if depth < range.min || depth > range.max {
            return fallback(FallbackReason::OutOfRange { depth });
        }
        Ok(Fixation::Converged {
            point,
            s,
            t,
            depth,
            gap: norm(sub(pp, qq)),
        })
    }

    fn along_gaze(&self, depth: f64) -> [f64; 3] {
        add(self.m, scale(self.g, depth))
    }

    /// `p` moved radially from m so its depth is in range; None if p is not in front of the rig.
    fn clamp_depth(&self, p: [f64; 3], range: &DepthRange) -> Option<([f64; 3], f64)> {
        let v = sub(p, self.m);
        let depth = dot(v, self.g);
        if !finite(p) || !depth.is_finite() || depth <= 0.0 {
            return None;
        }
        let clamped = depth.clamp(range.min, range.max);
        if clamped == depth {
            return Some((p, depth));
        }
        Some((add(self.m, scale(v, clamped / depth)), clamped))
    }

    fn resolve(&self, range: &DepthRange, gaze_depth: Option<f64>, last: Option<[f64; 3]>) -> Result<ResolvedFixation> {
        let reason = match self.solve(range)? {
            Fixation::Converged { point, depth, .. } => {
                return Ok(ResolvedFixation {
                    point,
                    depth,
                    source: FixationSource::Vergence,
                })
            }
            Fixation::Fallback { reason } => reason,
        };
        if let Some(z) = gaze_depth.filter(|z| z.is_finite() && *z > 0.0) {
            let depth = z.clamp(range.min, range.max);
            return Ok(ResolvedFixation {
                point: self.along_gaze(depth),
                depth,
                source: FixationSource::GazePixelDepth(reason),
            });
        }
        if let Some((point, depth)) = last.and_then(|p| self.clamp_depth(p, range)) {
            return Ok(ResolvedFixation {
                point,
                depth,
                source: FixationSource::LastFixation(reason),
            });
        }
        Ok(ResolvedFixation {
            point: self.along_gaze(range.max),
            depth: range.max,
            source: FixationSource::MaxDepth(reason),
        })
    }
}

/// Closed-form fixation of two gaze rays: `r = o1 - o2`, `b = d1.d2`, `c = d1.r`, `f = d2.r`,
/// `den = 1 - b^2`, `s = (b f - c) / den`, `t = (f - b c) / den`, midpoint of o1 + s d1 and
/// o2 + t d2. Falls back, in this order, on equal origins, `den < MIN_DEN`, `s <= 0 || t <= 0`,
/// and depth outside `range`.
///
/// Errors: non-finite or zero directions, non-finite origins, opposite gazes, overflow.
pub fn vergence_fixation(left: &GazeRay, right: &GazeRay, range: &DepthRange) -> Result<Fixation> {
    Rig::new(left, right)?.solve(range)
}

/// [`vergence_fixation`], then on fallback: the depth sampled at the gaze pixel (`gaze_depth`,
/// distance along the mean gaze from the eye midpoint; ignored unless finite and > 0, clamped to
/// the range), else `last` moved radially into the range (ignored unless in front of the eyes),
/// else `range.max()` along the mean gaze.
pub fn resolve_fixation(
    left: &GazeRay,
    right: &GazeRay,
    range: &DepthRange,
    gaze_depth: Option<f64>,
    last: Option<[f64; 3]>,
) -> Result<ResolvedFixation> {
    Rig::new(left, right)?.resolve(range, gaze_depth, last)
}

/// Exponential smoothing of the resolved fixation: `F = F_prev + alpha (F_new - F_prev)`, with the
/// smoothed point's depth clamped to the range for the current eye positions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixationFilter {
    alpha: f64,
    range: DepthRange,
    last: Option<[f64; 3]>,
}

impl FixationFilter {
    /// `alpha` in (0, 1]: 1 is no smoothing; the seed suggests 0.05 to 0.3.
    pub fn new(alpha: f64, range: DepthRange) -> Result<Self> {
        if !(alpha > 0.0 && alpha <= 1.0) {
            return Err(Error::param(
                "fixation smoothing alpha",
                format!("{alpha} outside (0, 1]"),
            ));
        }
        Ok(FixationFilter {
            alpha,
            range,
            last: None,
        })
    }

    /// The last smoothed fixation, if any.
    pub fn last(&self) -> Option<[f64; 3]> {
        self.last
    }

    /// Forgets the history (a cut: the next frame is not smoothed towards the last).
    pub fn reset(&mut self) {
        self.last = None;
    }

    /// Resolves this frame's fixation (falling back on the previous output) and smooths it. The
    /// returned source is the branch that produced the unsmoothed target.
    pub fn update(&mut self, left: &GazeRay, right: &GazeRay, gaze_depth: Option<f64>) -> Result<ResolvedFixation> {
        let rig = Rig::new(left, right)?;
        let target = rig.resolve(&self.range, gaze_depth, self.last)?;
        let smoothed = match self.last {
            None => target.point,
            Some(prev) => add(prev, scale(sub(target.point, prev), self.alpha)),
        };
        let (point, depth) = rig
            .clamp_depth(smoothed, &self.range)
            .unwrap_or((target.point, target.depth));
        self.last = Some(point);
        Ok(ResolvedFixation {
            point,
            depth,
            source: target.source,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const U: f64 = f64::EPSILON / 2.0;

    use crate::test_rng::Rng;

    /// Random directions and frames on top of the shared test generator.
    trait Geometry {
        fn unit(&mut self) -> [f64; 3];
        fn frame(&mut self) -> [[f64; 3]; 3];
    }

    impl Geometry for Rng {
        fn unit(&mut self) -> [f64; 3] {
            loop {
                let v = [self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0)];
                let n = norm(v);
                if n > 0.1 && n <= 1.0 {
                    return scale(v, 1.0 / n);
                }
            }
        }
        /// Random orthonormal head frame (forward, right, up).
        fn frame(&mut self) -> [[f64; 3]; 3] {
            let fwd = self.unit();
            let a = self.unit();
            let right = sub(a, scale(fwd, dot(a, fwd)));
            let right = scale(right, 1.0 / norm(right));
            let up = [
                fwd[1] * right[2] - fwd[2] * right[1],
                fwd[2] * right[0] - fwd[0] * right[2],
                fwd[0] * right[1] - fwd[1] * right[0],
            ];
            [fwd, right, up]
        }
    }

    /// Independent reference: minimise |o1 + s D1 - o2 - t D2|^2 over (s, t) with the
    /// un-normalised directions, normal equations [A -B; B -C] (s, t) = (-D1.r, -D2.r) solved by
    /// Cramer's rule. Returns the midpoint and s, t as distances.
    fn least_squares(o1: [f64; 3], dd1: [f64; 3], o2: [f64; 3], dd2: [f64; 3]) -> ([f64; 3], f64, f64) {
        let r = sub(o1, o2);
        let (a, b, c) = (dot(dd1, dd1), dot(dd1, dd2), dot(dd2, dd2));
        let (e, f) = (dot(dd1, r), dot(dd2, r));
        let det = b * b - a * c;
        let s = (c * e - b * f) / det;
        let t = (b * e - a * f) / det;
        let mid = scale(add(add(o1, scale(dd1, s)), add(o2, scale(dd2, t))), 0.5);
        (mid, s * a.sqrt(), t * c.sqrt())
    }

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Expect {
        Converged(Option<[f64; 3]>),
        ZeroBaseline,
        Parallel,
        Behind,
        OutOfRange,
        /// Decided from the reference solve in the test.
        Unknown,
    }

    struct Case {
        left: GazeRay,
        right: GazeRay,
        expect: Expect,
    }

    fn rays(o1: [f64; 3], d1: [f64; 3], o2: [f64; 3], d2: [f64; 3]) -> (GazeRay, GazeRay) {
        (
            GazeRay {
                origin: o1,
                direction: d1,
            },
            GazeRay {
                origin: o2,
                direction: d2,
            },
        )
    }

    /// Range used by the random cases.
    fn range() -> DepthRange {
        DepthRange::new(0.1, 20.0).unwrap()
    }

    fn random_case(rng: &mut Rng, kind: u32) -> Case {
        let [fwd, right, up] = rng.frame();
        let m = [rng.range(-5.0, 5.0), rng.range(-5.0, 5.0), rng.range(-5.0, 5.0)];
        let ipd = rng.range(0.05, 0.08);
        let o1 = sub(m, scale(right, 0.5 * ipd));
        let o2 = add(m, scale(right, 0.5 * ipd));
        // A target in front of the head, off-axis by up to ~30 degrees.
        let target = |rng: &mut Rng, d: f64| {
            let dir = add(
                add(fwd, scale(right, rng.range(-0.5, 0.5))),
                scale(up, rng.range(-0.5, 0.5)),
            );
            add(m, scale(dir, d / norm(dir)))
        };
        let mut target_at = |lo: f64, hi: f64| {
            let d = rng.range(lo, hi);
            target(rng, d)
        };
        let (left, right_ray, expect) = match kind {
            0 => {
                let f = target_at(0.3, 15.0);
                let (l, r) = rays(o1, sub(f, o1), o2, sub(f, o2));
                (l, r, Expect::Converged(Some(f)))
            }
            1 => {
                // Skew: a vertical misalignment of up to 1 mrad.
                let f = target_at(0.3, 10.0);
                let d1 = add(
                    scale(sub(f, o1), 1.0 / norm(sub(f, o1))),
                    scale(up, rng.range(-1e-3, 1e-3)),
                );
                let d2 = add(
                    scale(sub(f, o2), 1.0 / norm(sub(f, o2))),
                    scale(up, rng.range(-1e-3, 1e-3)),
                );
                let (l, r) = rays(o1, d1, o2, d2);
                (l, r, Expect::Converged(None))
            }
            2 => {
                // d1 . d2 within 1e-9 of 1 (sometimes exactly equal directions).
                let d1 = sub(target_at(1.0, 1.0), m);
                let d1 = scale(d1, 1.0 / norm(d1));
                let w = sub(up, scale(d1, dot(up, d1)));
                let w = scale(w, 1.0 / norm(w));
                let alpha = if rng.next_u64().is_multiple_of(4) {
                    0.0
                } else {
                    (2.0 * rng.range(0.0, 1e-9)).sqrt()
                };
                let d2 = add(scale(d1, alpha.cos()), scale(w, alpha.sin()));
                assert!(1.0 - dot(unit("", d1).unwrap(), unit("", d2).unwrap()) <= 1e-9 + 4.0 * U);
                let (l, r) = rays(o1, d1, o2, d2);
                (l, r, Expect::Parallel)
            }
            3 => {
                // Diverging: the lines meet behind the head.
                let back = sub(m, scale(fwd, rng.range(0.3, 10.0)));
                let (l, r) = rays(o1, sub(o1, back), o2, sub(o2, back));
                (l, r, Expect::Behind)
            }
            4 => {
                let (l, r) = rays(o1, sub(target_at(1.0, 1.0), o1), o1, sub(target_at(2.0, 2.0), o1));
                (l, r, Expect::ZeroBaseline)
            }
            5 => {
                let f = target_at(25.0, 200.0);
                let (l, r) = rays(o1, sub(f, o1), o2, sub(f, o2));
                (l, r, Expect::OutOfRange)
            }
            6 => {
                let f = target_at(0.02, 0.08);
                let (l, r) = rays(o1, sub(f, o1), o2, sub(f, o2));
                (l, r, Expect::OutOfRange)
            }
            _ => {
                let o1 = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
                let o2 = add(o1, scale(rng.unit(), rng.range(0.01, 2.0)));
                let (l, r) = rays(o1, scale(rng.unit(), rng.range(0.1, 10.0)), o2, scale(rng.unit(), 3.0));
                (l, r, Expect::Unknown)
            }
        };
        Case {
            left,
            right: right_ray,
            expect,
        }
    }

    /// Expected branch from the reference solve; None when within a margin of a boundary.
    fn reference_branch(case: &Case, range: &DepthRange) -> Option<Expect> {
        let (o1, o2) = (case.left.origin, case.right.origin);
        let (dd1, dd2) = (case.left.direction, case.right.direction);
        if o1 == o2 {
            return Some(Expect::ZeroBaseline);
        }
        let cos = dot(dd1, dd2) / (norm(dd1) * norm(dd2));
        let den = 1.0 - cos * cos;
        if den < 0.5 * MIN_DEN {
            return Some(Expect::Parallel);
        }
        if den < 2.0 * MIN_DEN {
            return None;
        }
        let (mid, s, t) = least_squares(o1, dd1, o2, dd2);
        let scale_l = s.abs() + t.abs() + norm(sub(o1, o2));
        let tol = 1e3 * ERROR_GAIN * U * scale_l / den;
        if s.abs() < tol || t.abs() < tol {
            return None;
        }
        if s <= 0.0 || t <= 0.0 {
            return Some(Expect::Behind);
        }
        let g = add(scale(dd1, 1.0 / norm(dd1)), scale(dd2, 1.0 / norm(dd2)));
        let depth = dot(sub(mid, scale(add(o1, o2), 0.5)), scale(g, 1.0 / norm(g)));
        if (depth - range.min).abs() < tol || (depth - range.max).abs() < tol {
            return None;
        }
        Some(if depth < range.min || depth > range.max {
            Expect::OutOfRange
        } else {
            Expect::Converged(None)
        })
    }

    fn assert_finite(f: &Fixation) {
        match *f {
            Fixation::Converged {
                point,
                s,
                t,
                depth,
                gap,
            } => assert!(
                finite(point) && [s, t, depth, gap].iter().all(|v| v.is_finite()),
                "{f:?}"
            ),
            Fixation::Fallback { reason } => match reason {
                FallbackReason::ZeroBaseline => {}
                FallbackReason::NearlyParallel { den } => assert!(den.is_finite()),
                FallbackReason::BehindEye { s, t } => assert!(s.is_finite() && t.is_finite()),
                FallbackReason::OutOfRange { depth } => assert!(depth.is_finite()),
            },
        }
    }

    #[test]
    fn random_rigs_take_the_documented_branch_and_match_least_squares() {
        let mut rng = Rng(0x0123_4567_89AB_CDEF);
        let range = range();
        let mut counts = [0usize; 8];
        let (mut skipped, mut max_ratio, mut max_exact_ratio) = (0usize, 0.0f64, 0.0f64);
        for i in 0..40_000u32 {
            let kind = i % 8;
            let case = random_case(&mut rng, kind);
            let got = vergence_fixation(&case.left, &case.right, &range).unwrap();
            assert_finite(&got);
            let expect = match case.expect {
                Expect::Unknown => match reference_branch(&case, &range) {
                    Some(e) => e,
                    None => {
                        skipped += 1;
                        continue;
                    }
                },
                e => e,
            };
            let branch_ok = match (expect, got) {
                (Expect::Converged(_), Fixation::Converged { .. }) => true,
                (Expect::ZeroBaseline, Fixation::Fallback { reason }) => reason == FallbackReason::ZeroBaseline,
                (Expect::Parallel, Fixation::Fallback { reason }) => {
                    matches!(reason, FallbackReason::NearlyParallel { .. })
                }
                (Expect::Behind, Fixation::Fallback { reason }) => matches!(reason, FallbackReason::BehindEye { .. }),
                (Expect::OutOfRange, Fixation::Fallback { reason }) => {
                    matches!(reason, FallbackReason::OutOfRange { .. })
                }
                _ => false,
            };
            assert!(branch_ok, "case {i} kind {kind}: expected {expect:?}, got {got:?}");
            counts[kind as usize] += 1;
            if let Fixation::Converged { point, s, t, .. } = got {
                let (o1, o2) = (case.left.origin, case.right.origin);
                let (d1, d2) = (
                    unit("", case.left.direction).unwrap(),
                    unit("", case.right.direction).unwrap(),
                );
                let den = 1.0 - dot(d1, d2).powi(2);
                let scale_l = s.abs() + t.abs() + norm(sub(o1, o2));
                // Closed-form bound plus rounding of the final additions at the origins' magnitude.
                let bound = U * (ERROR_GAIN * scale_l / den + 4.0 * (norm(o1) + norm(o2) + scale_l));
                let (mid, _, _) = least_squares(o1, case.left.direction, o2, case.right.direction);
                // Both solvers obey the bound: their difference is within twice it.
                let ratio = norm(sub(point, mid)) / bound;
                max_ratio = max_ratio.max(ratio);
                assert!(
                    ratio <= 2.0,
                    "case {i}: |closed - lsq| = {} > 2 x {bound}",
                    norm(sub(point, mid))
                );
                if let Expect::Converged(Some(f)) = case.expect {
                    let ratio = norm(sub(point, f)) / bound;
                    max_exact_ratio = max_exact_ratio.max(ratio);
                    assert!(
                        ratio <= 1.0,
                        "case {i}: |closed - exact| = {} > {bound}",
                        norm(sub(point, f))
                    );
                }
            }
        }
        eprintln!(
            "per kind {counts:?}, skipped {skipped}, max |closed - lsq| / bound = {max_ratio:.3e}, \
             max |closed - exact| / bound = {max_exact_ratio:.3e}"
        );
        assert!(counts.iter().all(|&n| n > 1000), "{counts:?}");
        assert!(skipped < 50, "{skipped}");
    }

    #[test]
    fn exactly_intersecting_well_conditioned_rays_return_the_intersection_to_1e_12() {
        let mut rng = Rng(99);
        let range = DepthRange::new(1e-3, 1e3).unwrap();
        let mut worst = 0.0f64;
        for _ in 0..20_000 {
            let o1 = [rng.range(-2.0, 2.0), rng.range(-2.0, 2.0), rng.range(-2.0, 2.0)];
            let o2 = add(o1, scale(rng.unit(), rng.range(0.5, 2.0)));
            let f = add(scale(add(o1, o2), 0.5), scale(rng.unit(), rng.range(0.5, 3.0)));
            let (d1, d2) = (sub(f, o1), sub(f, o2));
            let cos = dot(d1, d2) / (norm(d1) * norm(d2));
            if 1.0 - cos * cos < 0.05 {
                continue;
            }
            let (l, r) = rays(o1, d1, o2, d2);
            match vergence_fixation(&l, &r, &range).unwrap() {
                Fixation::Converged { point, gap, .. } => {
                    let rel = norm(sub(point, f)) / norm(f).max(1.0);
                    worst = worst.max(rel);
                    assert!(rel <= 1e-12, "{rel:e}");
                    assert!(gap <= 1e-12 * norm(f).max(1.0));
                }
                other => panic!("{other:?}"),
            }
        }
        eprintln!("worst relative error of exact intersections: {worst:.3e}");
    }

    #[test]
    fn threshold_is_where_the_documented_error_bound_reaches_1e_6() {
        // K u / MIN_DEN is the bound's relative size at the threshold: below 1e-6.
        const { assert!(ERROR_GAIN * U / MIN_DEN < 1e-6) };
        // Just above and just below the threshold: converged vs parallel, for rays that do meet.
        let o1 = [-0.032, 0.0, 0.0];
        let o2 = [0.032, 0.0, 0.0];
        let far = DepthRange::new(0.1, 1e9).unwrap();
        for (sin, parallel) in [(2e-4, false), (0.5e-4, true)] {
            // Symmetric vergence with half-angle a: den = sin^2(2a).
            let a: f64 = 0.5 * f64::asin(sin);
            let (l, r) = rays(o1, [a.sin(), 0.0, a.cos()], o2, [-a.sin(), 0.0, a.cos()]);
            let got = vergence_fixation(&l, &r, &far).unwrap();
            assert_eq!(
                matches!(
                    got,
                    Fixation::Fallback {
                        reason: FallbackReason::NearlyParallel { .. }
                    }
                ),
                parallel
            );
            if let Fixation::Converged { point, .. } = got {
                let z = 0.032 / a.tan();
                assert!((point[2] - z).abs() <= 1e-6 * z, "{point:?} vs {z}");
            }
        }
    }

    #[test]
    fn zero_ipd_always_falls_back() {
        let o = [0.3, -1.0, 2.0];
        let range = range();
        for (d1, d2) in [([0.0, 0.0, 1.0], [0.1, 0.0, 1.0]), ([0.0, 0.0, 1.0], [0.0, 0.0, 1.0])] {
            let (l, r) = rays(o, d1, o, d2);
            assert_eq!(
                vergence_fixation(&l, &r, &range).unwrap(),
                Fixation::Fallback {
                    reason: FallbackReason::ZeroBaseline
                }
            );
            let res = resolve_fixation(&l, &r, &range, None, None).unwrap();
            assert_eq!(res.source, FixationSource::MaxDepth(FallbackReason::ZeroBaseline));
            assert!(finite(res.point) && res.depth == 20.0);
        }
    }

    #[test]
    fn fallback_chain_follows_the_documented_order() {
        let mut rng = Rng(5);
        let range = range();
        for i in 0..20_000u32 {
            let case = random_case(&mut rng, i % 8);
            let rig = Rig::new(&case.left, &case.right).unwrap();
            let gaze = match rng.next_u64() % 6 {
                0 => None,
                1 => Some(f64::NAN),
                2 => Some(f64::INFINITY),
                3 => Some(-1.0),
                _ => Some(rng.range(0.01, 30.0)),
            };
            let last = match rng.next_u64() % 3 {
                0 => None,
                1 => Some(add(rig.m, scale(rng.unit(), rng.range(0.01, 40.0)))),
                _ => Some([f64::NAN, 0.0, 0.0]),
            };
            let got = resolve_fixation(&case.left, &case.right, &range, gaze, last).unwrap();
            assert!(finite(got.point) && got.depth.is_finite());
            assert!(got.depth >= range.min() && got.depth <= range.max(), "{got:?}");
            let actual_depth = dot(sub(got.point, rig.m), rig.g);
            assert!((actual_depth - got.depth).abs() <= 1e-12 * got.depth.max(1.0) + 1e-12 * norm(rig.m));
            match vergence_fixation(&case.left, &case.right, &range).unwrap() {
                Fixation::Converged { point, .. } => {
                    assert_eq!(got.source, FixationSource::Vergence);
                    assert_eq!(got.point, point);
                }
                Fixation::Fallback { reason } => {
                    let gaze_ok = gaze.filter(|z| z.is_finite() && *z > 0.0);
                    let last_depth = last.filter(|p| finite(*p)).map(|p| dot(sub(p, rig.m), rig.g));
                    if let Some(z) = gaze_ok {
                        assert_eq!(got.source, FixationSource::GazePixelDepth(reason));
                        assert_eq!(got.depth, z.clamp(range.min(), range.max()));
                    } else if last_depth.is_some_and(|d| d > 0.0) {
                        assert_eq!(got.source, FixationSource::LastFixation(reason));
                        let d = last_depth.unwrap();
                        if (range.min()..=range.max()).contains(&d) {
                            assert_eq!(got.point, last.unwrap());
                        }
                    } else {
                        assert_eq!(got.source, FixationSource::MaxDepth(reason));
                        assert_eq!(got.depth, range.max());
                    }
                }
            }
        }
    }

    #[test]
    fn filter_smooths_geometrically_and_clamps_depth() {
        let range = range();
        let o1 = [-0.032, 1.6, 0.0];
        let o2 = [0.032, 1.6, 0.0];
        let at = |f: [f64; 3]| rays(o1, sub(f, o1), o2, sub(f, o2));
        let (fa, fb) = ([0.1, 1.5, 2.0], [-0.2, 1.7, 0.7]);
        let mut filter = FixationFilter::new(0.25, range).unwrap();
        let (l, r) = at(fa);
        let first = filter.update(&l, &r, None).unwrap();
        assert_eq!(first.source, FixationSource::Vergence);
        // K u (|s| + |t| + |r|) / den with den ~ (0.064 / 2)^2: about 7e-12.
        assert!(norm(sub(first.point, fa)) <= 1e-11);
        let (l, r) = at(fb);
        let target = resolve_fixation(&l, &r, &range, None, None).unwrap().point;
        for n in 1..=40 {
            let out = filter.update(&l, &r, None).unwrap();
            let k = 0.75f64.powi(n);
            let want = add(target, scale(sub(first.point, target), k));
            assert!(norm(sub(out.point, want)) <= 1e-13, "n={n}");
        }
        // A fixation left out of range by a head move is clamped back to the range.
        let mut filter = FixationFilter::new(0.5, range).unwrap();
        let (l, r) = at([0.0, 1.6, 19.0]);
        filter.update(&l, &r, None).unwrap();
        let back = |o: [f64; 3]| [o[0], o[1], o[2] - 10.0];
        let (l, r) = rays(back(o1), [0.0, 0.0, 1.0], back(o2), [0.0, 0.0, 1.0]);
        let out = filter.update(&l, &r, None).unwrap();
        assert!(matches!(
            out.source,
            FixationSource::LastFixation(FallbackReason::NearlyParallel { .. })
        ));
        assert_eq!(out.depth, 20.0);
        assert!((out.point[2] - 10.0).abs() <= 1e-12, "{out:?}");
        filter.reset();
        assert_eq!(filter.last(), None);
        for alpha in [0.0, -0.1, 1.5, f64::NAN] {
            assert!(FixationFilter::new(alpha, range).is_err(), "{alpha}");
        }
    }

    #[test]
    fn filter_outputs_stay_finite_and_in_range_over_random_sequences() {
        let mut rng = Rng(77);
        let range = range();
        let mut filter = FixationFilter::new(0.1, range).unwrap();
        for i in 0..20_000u32 {
            let kind = (rng.next_u64() % 8) as u32;
            let case = random_case(&mut rng, kind);
            let gaze = (i % 3 == 0).then(|| rng.range(0.0, 30.0));
            let out = filter.update(&case.left, &case.right, gaze).unwrap();
            assert!(
                finite(out.point) && out.depth >= range.min() && out.depth <= range.max(),
                "{out:?}"
            );
        }
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let range = range();
        let ok = GazeRay {
            origin: [0.0; 3],
            direction: [0.0, 0.0, 1.0],
        };
        let bad = [
            GazeRay {
                origin: [f64::NAN, 0.0, 0.0],
                ..ok
            },
            GazeRay {
                direction: [0.0; 3],
                ..ok
            },
            GazeRay {
                direction: [f64::INFINITY, 0.0, 1.0],
                ..ok
            },
            GazeRay {
                direction: [0.0, 0.0, -1.0],
                origin: [0.064, 0.0, 0.0],
            },
        ];
        for b in &bad {
            assert!(vergence_fixation(&ok, b, &range).is_err(), "{b:?}");
            assert!(resolve_fixation(&ok, b, &range, Some(1.0), None).is_err(), "{b:?}");
        }
        // Tiny and huge direction vectors are fine (normalised without under/overflow).
        let tiny = GazeRay {
            origin: [0.064, 0.0, 0.0],
            direction: [-0.064e-300, 0.0, 1e-300],
        };
        let huge = GazeRay {
            origin: [0.0; 3],
            direction: [0.0, 0.0, 1e300],
        };
        assert!(matches!(
            vergence_fixation(&huge, &tiny, &range).unwrap(),
            Fixation::Converged { .. }
        ));
        for (lo, hi) in [
            (0.0, 1.0),
            (1.0, 1.0),
            (2.0, 1.0),
            (0.1, f64::INFINITY),
            (f64::NAN, 1.0),
        ] {
            assert!(DepthRange::new(lo, hi).is_err(), "{lo} {hi}");
        }
    }
}
