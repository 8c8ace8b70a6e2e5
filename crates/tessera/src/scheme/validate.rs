//! What a request may be: the one place that decides which scheme × criterion × surface kind ×
//! engine combinations tessera draws, and with which caps.
//!
//! [`validate`] is called by [`Scheme::plan`] (so by the [`crate::tessellator::Tessellator`]
//! too), by the GPU engine before it plans a frame from the camera (tessera-gpu's
//! `prepare_screen`) and by the command-line tool before it starts any work, so a combination
//! is refused with the same typed [`Error`] wherever it is asked for, before anything of the
//! output's size is computed. Everything here is O(1) but the surface-kind check of the
//! schemes defined for one kind, which is O(P).

use super::{Criterion, PlanOptions, Scheme};
use crate::criterion::resolve::{EdgeRule, InteriorRule};
use crate::criterion::view::ViewCriterion;
use crate::criterion::MAX_FACTOR;
use crate::domain::Domain;
use crate::error::{Error, Result};
use crate::pattern::hardware::Hardware;
use crate::pattern::semi_uniform::{SemiUniform, MAX_LEVEL as SEMI_UNIFORM_MAX_LEVEL};
use crate::pattern::transition::Transition;
use crate::pattern::uniform::Uniform;
use crate::pattern::Pattern;
use crate::surface::{Patch, SurfaceSet};

/// The engine that is to draw a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Engine {
    /// The CPU engine ([`crate::engine`]): every scheme and criterion.
    Cpu,
    /// The GPU engine (tessera-gpu) drawing a plan made on the CPU: the uniform, transition,
    /// semi-uniform (compacted), SD-2 and Direct3D 11 schemes.
    Gpu,
    /// The GPU engine planning every frame itself from the camera (CudaTess's frame): culling
    /// on, and a pixel error with the uniform, transition or semi-uniform scheme (the latter
    /// two's a-posteriori check with caps up to [`GPU_CHECK_MAX_FACTOR`]), silhouetteness
    /// with those or a Direct3D 11 partitioning, a fixed factor with a partitioning, or
    /// SD-2's level functions (distance, vertex silhouettes) and fixed factor.
    GpuFromCamera,
}

impl Engine {
    /// The name messages use.
    pub fn name(self) -> &'static str {
        match self {
            Engine::Cpu => "CPU",
            Engine::Gpu => "GPU",
            Engine::GpuFromCamera => "GPU's own frame planning",
        }
    }
}

/// The largest factor cap of a frame whose a-posteriori check runs on the GPU (the CPU's
/// default cap). The GPU's shaders rely on it: a check walks strips of at most 2 · 64 steps,
/// so the loops of one invocation stay well within the 65,535 iterations Mesa's lavapipe
/// allows an invocation in all (about 21,000 at the worst: 39 interior steps of four
/// strips), and `bounds.wgsl`'s test for sides along an axis tells exact arithmetic's answer
/// in f32 only while factors are at most 64.
pub const GPU_CHECK_MAX_FACTOR: u32 = 64;

/// What [`validate`] decided beside "yes": the rules the plan follows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accepted {
    /// The largest edge factor the plan may use: the scheme's own cap and
    /// [`PlanOptions::max_factor`], a power of two for semi-uniform (its highest level).
    pub cap: f64,
    /// How resolved factors become edge samplings (None for ESC).
    pub edge_rule: Option<EdgeRule>,
    /// How interior factors follow from the edges.
    pub interior_rule: InteriorRule,
}

/// Decides whether `scheme` draws `set` under `criterion` and `options` on `engine`, and with
/// which caps and rules.
///
/// Errors, all [`Error`]: [`Error::CriterionNotAccepted`] (the pairing, [`Scheme::accepts`]),
/// [`Error::FactorOutOfRange`] (a factor or factor range the scheme cannot draw),
/// [`Error::InvalidParameter`] (the max factor, the max level, a tolerance or pixel error
/// that is not a positive number, culling with ESC), [`Error::PatchKindNotAccepted`] (SD-2's
/// quads, ESC's triangles, naming the first such patch) and [`Error::EngineNotSupported`]
/// (what the engine does not do). A missing camera is the planner's to report
/// ([`Error::NeedsCamera`]): whether one is needed depends on the frame. Cost: O(1), O(P) for
/// SD-2 and ESC.
pub fn validate(
    scheme: Scheme,
    criterion: &Criterion,
    options: &PlanOptions,
    set: &SurfaceSet,
    engine: Engine,
) -> Result<Accepted> {
    check_request(scheme, criterion, options)?;
    check_surface_kinds(scheme, set)?;
    check_engine(scheme, criterion, options, engine)?;
    if engine != Engine::Cpu {
        let promised = match scheme {
            Scheme::Uniform => Uniform.cut_through_corners_0_and_2(),
            Scheme::Transition => Transition.cut_through_corners_0_and_2(),
            Scheme::SemiUniform { .. } => SemiUniform.cut_through_corners_0_and_2(),
            Scheme::Hardware(partitioning) => Hardware { partitioning }.cut_through_corners_0_and_2(),
            // SD-2 takes triangles and ESC no tree: neither meets a pinched corner.
            Scheme::Sd2 { .. } | Scheme::Esc { .. } => false,
        };
        if let Some(p) = pinched_beyond_the_gpu(set, promised) {
            return Err(Error::EngineNotSupported { engine: engine.name(), what: pinched_on_gpu(p) });
        }
    }
    Ok(Accepted {
        cap: scheme.cap(options),
        edge_rule: scheme.edge_rule(),
        interior_rule: scheme.interior_rule(),
    })
}

impl Scheme {
    /// The largest factor the scheme may use under `options` ([`Accepted::cap`]): its own
    /// cap ([`Scheme::factor_cap`]) and `max_factor`, a power of two for semi-uniform (its
    /// highest level). Cost: O(1).
    pub fn cap(&self, options: &PlanOptions) -> f64 {
        let cap = self.factor_cap().min(options.max_factor.max(1) as f64);
        match self {
            Scheme::SemiUniform { .. } => (1u32 << (31 - (cap as u32).leading_zeros())) as f64,
            _ => cap,
        }
    }

    /// Whether the scheme accepts `criterion`; the error names what it accepts instead.
    /// Part of [`validate`]. Cost: O(1).
    pub fn accepts(&self, criterion: &Criterion) -> Result<()> {
        let refuse = |hint: &str| {
            Err(Error::CriterionNotAccepted {
                scheme: self.name(),
                criterion: criterion.name(),
                hint: hint.to_string(),
            })
        };
        match (self, criterion) {
            (Scheme::Esc { .. }, Criterion::Esc { .. }) => Ok(()),
            (Scheme::Esc { .. }, _) => refuse("ESC has its own criterion: a quality threshold and levels"),
            (_, Criterion::Esc { .. }) => refuse("the ESC criterion goes with the esc scheme only"),
            (
                Scheme::Sd2 { .. } | Scheme::Hardware(_),
                Criterion::Tolerance(_) | Criterion::PixelError(_),
            ) => refuse(
                "it gives no error guarantee: use a factor or a view criterion, or the uniform, \
                     transition or semi-uniform scheme for an error bound",
            ),
            (Scheme::Sd2 { .. }, Criterion::View { criterion: ViewCriterion::Silhouetteness, .. }) => {
                refuse("SD-2 needs a level function: use vertex silhouettes or distance factors")
            }
            _ => Ok(()),
        }
    }
}

/// The scheme × criterion × options part of [`validate`]: the pairing and every range.
fn check_request(scheme: Scheme, criterion: &Criterion, options: &PlanOptions) -> Result<()> {
    scheme.accepts(criterion)?;
    if options.max_factor == 0 || options.max_factor > MAX_FACTOR {
        return Err(Error::InvalidParameter {
            name: "max factor",
            reason: format!("{}: use 1 to {MAX_FACTOR}", options.max_factor),
        });
    }
    let name = scheme.name();
    let out_of_range =
        |factor: f64, expected: String| Err(Error::FactorOutOfRange { scheme: name, factor, expected });
    match (scheme, *criterion) {
        (Scheme::SemiUniform { max_level }, _) if max_level > SEMI_UNIFORM_MAX_LEVEL => {
            Err(Error::InvalidParameter {
                name: "max level",
                reason: format!("{max_level}: semi-uniform levels go from 0 to {SEMI_UNIFORM_MAX_LEVEL}"),
            })
        }
        (Scheme::Esc { max_level }, _) if max_level > crate::pattern::esc::MAX_LEVEL => {
            Err(Error::InvalidParameter {
                name: "max level",
                reason: format!("{max_level}: ESC levels go from 0 to {}", crate::pattern::esc::MAX_LEVEL),
            })
        }
        (Scheme::Esc { .. }, _) if options.cull => Err(Error::InvalidParameter {
            name: "cull",
            reason: "the esc scheme chooses one level per object and culls nothing".into(),
        }),
        (Scheme::Uniform | Scheme::Transition, Criterion::Factor(f)) => {
            if f.fract() != 0.0 || !(1.0..=MAX_FACTOR as f64).contains(&f) {
                return out_of_range(
                    f,
                    format!(
                        "an integer from 1 to {MAX_FACTOR} (real factors need the fractional-odd, \
                         fractional-even or sd2 scheme)"
                    ),
                );
            }
            Ok(())
        }
        (Scheme::SemiUniform { max_level }, Criterion::Factor(f)) => {
            let top = 1u32 << max_level;
            if f.fract() != 0.0 || !(1.0..=top as f64).contains(&f) || !(f as u32).is_power_of_two() {
                return out_of_range(f, format!("a power of two up to 2^{max_level} (the max level)"));
            }
            Ok(())
        }
        (Scheme::Sd2 { .. } | Scheme::Hardware(_), Criterion::Factor(f)) => {
            let hi = scheme.factor_cap().min(options.max_factor as f64);
            if !(f.is_finite() && f >= 1.0 && f <= hi) {
                let why = match scheme {
                    Scheme::Hardware(p) if hi == p.range().1 as f64 => {
                        format!("a number from 1 to {hi}, the hardware's {} range", p.name())
                    }
                    _ => format!("a number from 1 to the max factor {hi}"),
                };
                return out_of_range(f, why);
            }
            Ok(())
        }
        (_, Criterion::Tolerance(eps) | Criterion::PixelError(eps)) if !(eps.is_finite() && eps > 0.0) => {
            Err(Error::InvalidParameter {
                name: if matches!(criterion, Criterion::Tolerance(_)) { "tolerance" } else { "pixel error" },
                reason: format!("{eps}: must be a positive number"),
            })
        }
        (_, Criterion::View { fmin, fmax, .. }) => {
            let integer = matches!(scheme.edge_rule(), Some(EdgeRule::Integer | EdgeRule::PowerOfTwo));
            let valid = |f: f64| f.is_finite() && f >= 1.0 && (!integer || f.fract() == 0.0);
            if !(valid(fmin) && valid(fmax) && fmin <= fmax) {
                let what = if integer { "integers" } else { "numbers" };
                return out_of_range(
                    if valid(fmin) { fmax } else { fmin },
                    format!("a range FMIN:FMAX of {what} with 1 ≤ FMIN ≤ FMAX"),
                );
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// The first patch whose pinched corner (an interior vertex of valence 2 of a Catmull-Clark
/// cage, [`crate::topology::Topology::pinched_corners`]) the GPU's patterns would not cut:
/// they do not run `pattern::cut_pinched_corners`, so only a pattern that needs no cut at
/// corners 0 and 2 (`promised`: `Pattern::cut_through_corners_0_and_2`; the cage's patches
/// are turned to have their pinched corners there) draws such a patch as the CPU does, and
/// a patch pinched at corner 1 or 3 too (a face with such vertices at neighbouring corners)
/// never. Cost: O(P) when the set has pinched corners, else O(1).
pub fn pinched_beyond_the_gpu(set: &SurfaceSet, promised: bool) -> Option<usize> {
    set.topology.patch_pinched.iter().position(|c| if promised { c[1] || c[3] } else { c.iter().any(|&x| x) })
}

/// What the GPU engine refuses for [`pinched_beyond_the_gpu`]'s patch `p`.
pub fn pinched_on_gpu(p: usize) -> String {
    format!(
        "patch {p} has corners at interior vertices of valence 2 next to each other (the GPU's \
         patterns cut such a corner only at corners 0 and 2, where a face with one is turned to \
         have it): use the CPU engine"
    )
}

/// The surface-kind part of [`validate`]: SD-2 is defined for triangles (paper 001), ESC for
/// bicubic patches (paper 002); every other scheme and both engines take every kind.
fn check_surface_kinds(scheme: Scheme, set: &SurfaceSet) -> Result<()> {
    let (needs, kind, hint) = match scheme {
        Scheme::Sd2 { .. } => (
            Domain::Tri,
            "quad",
            "SD-2 is defined for triangles (paper 001); use the semi-uniform, hardware or transition scheme",
        ),
        Scheme::Esc { .. } => (
            Domain::Quad,
            "triangle",
            "ESC tessellates bicubic Bézier patches only (a mesh gives PN triangles)",
        ),
        _ => return Ok(()),
    };
    if let Some(patch) = set.patches.iter().position(|p| p.domain() != needs) {
        return Err(Error::PatchKindNotAccepted { scheme: scheme.name(), kind, patch, hint });
    }
    if matches!(scheme, Scheme::Esc { .. }) {
        if let Some(patch) = set.patches.iter().position(|p| matches!(p, Patch::Subdivision(_))) {
            return Err(Error::PatchKindNotAccepted {
                scheme: scheme.name(),
                kind: "piecewise subdivision",
                patch,
                hint: "ESC needs one bicubic control net per patch; the isolated faces of a cage (next to \
                       extraordinary vertices or creases) are piecewise: use the transition, semi-uniform or \
                       uniform scheme",
            });
        }
    }
    Ok(())
}

/// The engine part of [`validate`].
fn check_engine(scheme: Scheme, criterion: &Criterion, options: &PlanOptions, engine: Engine) -> Result<()> {
    let refuse = |what: String| Err(Error::EngineNotSupported { engine: engine.name(), what });
    let gpu_scheme = matches!(
        scheme,
        Scheme::Uniform
            | Scheme::Transition
            | Scheme::Hardware(_)
            | Scheme::SemiUniform { .. }
            | Scheme::Sd2 { .. }
            | Scheme::Esc { .. }
    );
    match engine {
        Engine::Cpu => Ok(()),
        Engine::Gpu | Engine::GpuFromCamera if !gpu_scheme => refuse(format!(
            "the {} scheme (it draws the uniform, transition, semi-uniform, SD-2, ESC, integer, pow2, \
             fractional-odd and fractional-even schemes)",
            scheme.name()
        )),
        Engine::Gpu => Ok(()),
        Engine::GpuFromCamera => {
            let planned_on_gpu = matches!(
                (scheme, criterion),
                (Scheme::Uniform | Scheme::Transition | Scheme::SemiUniform { .. }, Criterion::PixelError(_))
                    | (
                        Scheme::Uniform
                            | Scheme::Transition
                            | Scheme::SemiUniform { .. }
                            | Scheme::Hardware(_),
                        Criterion::View { criterion: ViewCriterion::Silhouetteness, .. }
                    )
                    | (Scheme::Hardware(_), Criterion::Factor(_))
                    | (Scheme::Esc { .. }, Criterion::Esc { .. })
                    | (
                        Scheme::Sd2 { .. },
                        Criterion::Factor(_)
                            | Criterion::View {
                                criterion: ViewCriterion::Distance(_) | ViewCriterion::SilhouetteVertices,
                                ..
                            }
                    )
            );
            if !planned_on_gpu {
                return refuse(format!(
                    "{} with the {} scheme planned on the GPU",
                    criterion.name(),
                    scheme.name()
                ));
            }
            // ESC's levels are per object and it culls nothing; every other frame planned on
            // the GPU culls.
            if !options.cull && !matches!(scheme, Scheme::Esc { .. }) {
                return refuse("a frame without culling (it culls every frame it plans)".into());
            }
            let checked = matches!(scheme, Scheme::Transition | Scheme::SemiUniform { .. })
                && matches!(criterion, Criterion::PixelError(_));
            if checked && options.max_factor > GPU_CHECK_MAX_FACTOR {
                return refuse(format!(
                    "the a-posteriori check on the GPU with a factor cap of {} (it takes caps up to \
                     {GPU_CHECK_MAX_FACTOR}; plan this frame on the CPU)",
                    options.max_factor
                ));
            }
            if checked && options.bound == crate::criterion::ErrorBound::Taylor {
                return refuse(
                    "the Taylor bound planned on the GPU (its check computes the second-derivative \
                     and expansion bounds, not the Taylor bound's sampled refinements: plan this \
                     frame on the CPU, or with ErrorBound::Expansion)"
                        .into(),
                );
            }
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::esc::Threshold;
    use crate::pattern::hardware::Partitioning;

    fn quads() -> SurfaceSet {
        super::super::tests::flat()
    }

    /// A cage with an interior vertex of valence 2: every scheme that takes its patches goes to
    /// the GPU (their patterns need no cut at corners 0 and 2, where its patches have the
    /// vertex); a patch pinched at corner 1 or 3 as well is refused there by name, not on
    /// the CPU.
    #[test]
    fn pinched_corners_go_to_the_gpu_at_corners_0_and_2_only() {
        let path = crate::test_support::data("subdivision/catmark_val2_interior.obj");
        let mesh = crate::io::obj::read_obj(&path).unwrap();
        let mut set = SurfaceSet::from_subdivision_cage(&mesh, &path, Default::default()).unwrap();
        let p = set.topology.patch_pinched.iter().position(|c| c.contains(&true)).expect("a pinched patch");
        assert!(set.topology.patch_pinched.iter().all(|c| !c[1] && !c[3]), "turned to corners 0 and 2");
        let o = PlanOptions::default();
        let schemes = [
            (Scheme::Uniform, Criterion::Factor(4.0)),
            (Scheme::Transition, Criterion::Tolerance(0.01)),
            (Scheme::SemiUniform { max_level: 5 }, Criterion::Factor(4.0)),
            (Scheme::Hardware(Partitioning::FractionalOdd), Criterion::Factor(5.5)),
        ];
        for (scheme, criterion) in schemes {
            validate(scheme, &criterion, &o, &set, Engine::Gpu).unwrap();
        }
        set.topology.patch_pinched[p][1] = true;
        for (scheme, criterion) in schemes {
            validate(scheme, &criterion, &o, &set, Engine::Cpu).unwrap();
            let e = validate(scheme, &criterion, &o, &set, Engine::Gpu).unwrap_err();
            assert!(matches!(e, Error::EngineNotSupported { .. }), "{e}");
            assert!(
                e.to_string().contains(&format!("patch {p} has corners at interior vertices of valence 2")),
                "{e}"
            );
        }
    }

    #[test]
    fn every_combination_is_decided_with_a_typed_error() {
        let set = quads();
        let o = PlanOptions::default();
        let culled = PlanOptions { cull: true, ..o };
        let v = |s, c: Criterion, o: &PlanOptions, e| validate(s, &c, o, &set, e);
        let silhouette = Criterion::View { criterion: ViewCriterion::Silhouetteness, fmin: 1.0, fmax: 8.0 };
        let odd = Scheme::Hardware(Partitioning::FractionalOdd);
        // The CPU draws everything a scheme accepts.
        v(Scheme::SemiUniform { max_level: 5 }, Criterion::Factor(8.0), &o, Engine::Cpu).unwrap();
        let esc = Criterion::Esc { threshold: Threshold::High, level: Some(1) };
        v(Scheme::Esc { max_level: 3 }, esc, &o, Engine::Cpu).unwrap();
        // The GPU: four scheme families; from the camera, four pairings, culled.
        let engine_refused = |r: Result<Accepted>| matches!(r, Err(Error::EngineNotSupported { .. }));
        v(Scheme::SemiUniform { max_level: 5 }, Criterion::Factor(8.0), &o, Engine::Gpu).unwrap();
        v(Scheme::Esc { max_level: 3 }, esc, &o, Engine::Gpu).unwrap();
        v(Scheme::Esc { max_level: 3 }, esc, &o, Engine::GpuFromCamera).unwrap();
        let tris = crate::scheme::tests::triangles();
        let on_tris = |s, c: Criterion, e| validate(s, &c, &o, &tris, e);
        on_tris(Scheme::Sd2 { warp: false }, Criterion::Factor(3.5), Engine::Gpu).unwrap();
        on_tris(Scheme::Sd2 { warp: true }, Criterion::Factor(3.5), Engine::Gpu).unwrap();
        v(odd, Criterion::Factor(5.5), &o, Engine::Gpu).unwrap();
        v(odd, Criterion::Factor(5.5), &culled, Engine::GpuFromCamera).unwrap();
        assert!(engine_refused(v(odd, Criterion::Factor(5.5), &o, Engine::GpuFromCamera)), "no culling");
        v(Scheme::Transition, silhouette, &culled, Engine::GpuFromCamera).unwrap();
        assert!(engine_refused(v(
            Scheme::Transition,
            Criterion::Tolerance(0.1),
            &culled,
            Engine::GpuFromCamera
        )));
        v(Scheme::Transition, Criterion::PixelError(0.5), &culled, Engine::GpuFromCamera).unwrap();
        let high_cap = PlanOptions { max_factor: GPU_CHECK_MAX_FACTOR + 1, ..culled };
        assert!(engine_refused(v(
            Scheme::Transition,
            Criterion::PixelError(0.5),
            &high_cap,
            Engine::GpuFromCamera
        )));
        v(Scheme::Uniform, Criterion::PixelError(0.5), &high_cap, Engine::GpuFromCamera).unwrap();
        let taylor = PlanOptions { bound: crate::criterion::ErrorBound::Taylor, ..culled };
        assert!(engine_refused(v(
            Scheme::Transition,
            Criterion::PixelError(0.5),
            &taylor,
            Engine::GpuFromCamera
        )));
        v(Scheme::Transition, Criterion::PixelError(0.5), &taylor, Engine::Gpu).unwrap();
        // The expansion bound is the GPU's own (`expansion.wgsl`).
        let expansion = PlanOptions { bound: crate::criterion::ErrorBound::Expansion, ..culled };
        v(Scheme::Transition, Criterion::PixelError(0.5), &expansion, Engine::GpuFromCamera).unwrap();
        // The request's own errors come first, the same for every engine.
        for engine in [Engine::Cpu, Engine::Gpu, Engine::GpuFromCamera] {
            assert!(matches!(
                v(Scheme::Transition, Criterion::PixelError(f64::NAN), &culled, engine),
                Err(Error::InvalidParameter { name: "pixel error", .. })
            ));
            assert!(matches!(
                v(odd, Criterion::Factor(65.0), &culled, engine),
                Err(Error::FactorOutOfRange { scheme: "fractional-odd", .. })
            ));
        }
        // Surface kinds: SD-2 draws triangles only.
        assert!(matches!(
            v(Scheme::Sd2 { warp: false }, Criterion::Factor(3.0), &o, Engine::Cpu),
            Err(Error::PatchKindNotAccepted { scheme: "sd2", kind: "quad", patch: 0, .. })
        ));
    }

    #[test]
    fn the_cap_is_the_schemes_and_the_max_factors_a_power_of_two_for_semi_uniform() {
        let set = quads();
        let cap = |s, max_factor| {
            let o = PlanOptions { max_factor, ..PlanOptions::default() };
            validate(s, &Criterion::Tolerance(0.1), &o, &set, Engine::Cpu).unwrap().cap
        };
        assert_eq!(cap(Scheme::Transition, 40), 40.0);
        assert_eq!(cap(Scheme::SemiUniform { max_level: 5 }, 64), 32.0);
        assert_eq!(cap(Scheme::SemiUniform { max_level: 5 }, 20), 16.0);
    }
}
