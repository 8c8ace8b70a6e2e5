//! # tessera
//!
//! Crack-free adaptive tessellation of parametric surfaces — PN triangles, cubic Bézier
//! triangles and bicubic rational Bézier patches — into one watertight indexed triangle mesh.
//!
//! ## The pipeline
//!
//! ```text
//! input ─► SurfaceSet ─► Criterion ─► resolve ─► Plan (edge samplings) ─► Pattern per patch ─► Engine ─► Mesh
//! ```
//!
//! 1. [`io`] reads the inputs — Newell patch files, cubic Bézier triangle files, and triangle
//!    meshes (OBJ, PLY, STL, glTF) for PN triangles — with errors naming file, line and reason;
//!    [`io::load`] picks the format by extension.
//! 2. [`surface::SurfaceSet`] holds the patches and their [`topology`]: shared boundary curves
//!    found by index and by welding coincident control points.
//! 3. A [`criterion`] proposes factors per use of each shared edge; one resolver
//!    ([`criterion::resolve`]) decides each edge's sampling from data all its patches agree on,
//!    which is what makes the output crack-free. The [`criterion::Plan`] is plain arrays that
//!    every engine reads as they are.
//! 4. A [`pattern`] triangulates each patch's domain given its edges' samplings; patterns never
//!    evaluate surfaces.
//! 5. The [`engine`] counts, scans and writes in parallel; each shared edge vertex is evaluated
//!    once and referenced by every patch on it.
//! 6. [`mesh::Mesh`] holds the result, which [`io::write_mesh`] writes as OBJ, PLY, STL or glTF
//!    binary; [`verify`] checks watertightness, error and quality.
//!
//! ## Schemes
//!
//! Each published scheme is one [`scheme::Scheme`]: a pattern with its edge rule, interior
//! rule, caps and the criteria it accepts. What a scheme × criterion × surface kind × engine
//! accepts is decided in one function, [`scheme::validate`], which the
//! [`tessellator::Tessellator`], [`scheme::Scheme::plan`], the GPU engine and the command-line
//! tool all call: a request it cannot honour is refused up front with a typed [`Error`].
//!
//! | scheme | pattern | criteria | paper |
//! | --- | --- | --- | --- |
//! | `Uniform` | [`pattern::uniform`] | factor, [`criterion::tolerance`], [`criterion::screen`], [`criterion::view`] | the baseline |
//! | `Transition` | [`pattern::transition`] | the same | CudaTess (003) |
//! | `SemiUniform` | [`pattern::semi_uniform`] (+ [`engine::render_queues`] for the instanced form) | the same | Dyken et al. (000) |
//! | `Sd2` | [`pattern::sd2`] (strips) | factor, distance, vertex silhouettes ([`criterion::sd2`]) | Amresh & Fünfzig (001) |
//! | `Hardware` | [`pattern::hardware`] (integer, pow2, fractional odd/even) | factor, view | the Direct3D 11 tessellator |
//! | `Esc` | [`pattern::esc`] (strips) | its own ([`criterion::esc`]) | Concheiro et al. (002) |
//!
//! Patterns with a strip form fill [`mesh::Mesh::strips`] when
//! [`engine::EngineOptions::strips`] is set; [`mesh::strips::decode`] turns strips back
//! into the triangle list.
//!
//! ## Example
//!
//! The front door is a [`tessellator::Tessellator`]: a surface set prepared once for a
//! [`scheme::Scheme`] and a [`scheme::Criterion`], re-tessellated per frame into reused
//! buffers (`examples/frame_loop.rs` runs a 60-frame camera walk).
//!
//! ```
//! use tessera::scheme::{Criterion, Scheme};
//! use tessera::surface::SurfaceSet;
//! use tessera::tessellator::{Tessellator, TessellatorOptions};
//! use tessera::io::patches::parse_patches;
//! use std::path::Path;
//!
//! // One flat bicubic patch (the Newell format: counts, 1-based indices, points).
//! let mut text = String::from("1\n1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16\n16\n");
//! for i in 0..4 { for j in 0..4 { text += &format!("{i},{j},0\n"); } }
//! let file = parse_patches(&text, Path::new("<example>"))?;
//! let set = SurfaceSet::from_patch_file(&file, Default::default());
//! let mut tess = Tessellator::new(&set, Scheme::Uniform, Criterion::Factor(8.0), TessellatorOptions::default())?;
//! let mesh = tess.frame(None)?;
//! assert_eq!(mesh.triangle_count(), 2 * 8 * 8);
//! assert_eq!(mesh.vertex_count(), 9 * 9);
//! # Ok::<(), tessera::Error>(())
//! ```

pub mod camera;
mod cpu;
pub mod criterion;
pub mod domain;
pub mod engine;
pub mod error;
#[cfg(feature = "fuzzing")]
#[doc(hidden)]
pub mod fuzzing;
pub mod io;
pub mod mesh;
pub mod pattern;
pub mod sampling;
pub mod scene;
pub mod scheme;
pub mod subdivision;
pub mod surface;
pub mod tessellator;
#[cfg(any(test, feature = "fuzzing"))]
#[doc(hidden)]
pub mod test_support;
pub mod topology;
pub mod verify;

pub use error::{Error, Result};

/// The README's examples, compiled as doctests so they cannot go stale.
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
