//! The CPU↔GPU contract, checked: every uniform struct the engine writes, and every storage
//! struct it reads back by name, is laid out in Rust exactly as the WGSL declares it, member for member (names, offsets, size),
//! as naga (wgpu's shader compiler) lays the WGSL out. The codes the shaders compare against
//! (`INTERIOR_*`, `CRITERION_*`, `EDGE_RULE_*`, `PARTITIONING_*`) are not typed twice at all:
//! they are substituted into the WGSL from their Rust constants (`constants`), and a
//! placeholder left without a value panics at load. A reordered, retyped or missing field on
//! either side fails here instead of becoming a silent GPU bug.

use std::mem::{offset_of, size_of};

use crate::shader::sources::{COMMON, CULL, VIEW};
use crate::shader::{common_constants, expand};
use crate::tessellator::{constants, CheckRow, FrameState, Params, ViewUniform};

/// The module the cull pass compiles (`common.wgsl`, `view.wgsl`, `cull.wgsl`), expanded as
/// the engine expands it, parsed by naga.
fn cull_module() -> naga::Module {
    let mut all = common_constants();
    all.extend(constants());
    let text = expand(&[COMMON, VIEW, CULL].concat(), &all);
    naga::front::wgsl::parse_str(&text).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&text)))
}

/// The members (name, byte offset) and the size of the WGSL struct `name` in `module`.
fn wgsl_struct(module: &naga::Module, name: &str) -> (Vec<(String, u32)>, u32) {
    let ty = module
        .types
        .iter()
        .map(|(_, ty)| ty)
        .find(|ty| ty.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name} in the WGSL"));
    match &ty.inner {
        naga::TypeInner::Struct { members, span } => {
            (members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect(), *span)
        }
        other => panic!("{name} is not a struct: {other:?}"),
    }
}

/// Asserts that the WGSL struct `name` has `rust`'s members at `rust`'s offsets and
/// `rust_size` bytes. Padding members are compared by offset only (their names differ:
/// Rust pads with one array, WGSL with one member per word).
fn assert_same_layout(module: &naga::Module, name: &str, rust: &[(&str, usize)], rust_size: usize) {
    let (wgsl, size) = wgsl_struct(module, name);
    let named = |m: &[(String, u32)]| -> Vec<(String, u32)> {
        m.iter().filter(|(n, _)| !n.starts_with('_')).cloned().collect()
    };
    let rust: Vec<(String, u32)> = rust.iter().map(|&(n, o)| (n.to_string(), o as u32)).collect();
    assert_eq!(named(&wgsl), named(&rust), "{name}: the WGSL's members and offsets differ from Rust's");
    assert_eq!(size as usize, rust_size, "{name}: {size} bytes in WGSL, {rust_size} in Rust");
}

#[test]
fn shared_structs_match_their_wgsl_member_for_member() {
    let module = cull_module();
    assert_same_layout(
        &module,
        "Params",
        &[
            ("edges", offset_of!(Params, edges)),
            ("patches", offset_of!(Params, patches)),
            ("corners", offset_of!(Params, corners)),
            ("vertex_capacity", offset_of!(Params, vertex_capacity)),
            ("triangle_capacity", offset_of!(Params, triangle_capacity)),
            ("partitioning", offset_of!(Params, partitioning)),
            ("blocks", offset_of!(Params, blocks)),
            ("warped", offset_of!(Params, warped)),
        ],
        size_of::<Params>(),
    );
    assert_same_layout(
        &module,
        "View",
        &[
            ("eye", offset_of!(ViewUniform, eye)),
            ("right", offset_of!(ViewUniform, right)),
            ("up", offset_of!(ViewUniform, up)),
            ("forward", offset_of!(ViewUniform, forward)),
            ("near", offset_of!(ViewUniform, near)),
            ("far", offset_of!(ViewUniform, far)),
            ("tan_x", offset_of!(ViewUniform, tan_x)),
            ("tan_y", offset_of!(ViewUniform, tan_y)),
            ("focal", offset_of!(ViewUniform, focal)),
            ("pixels", offset_of!(ViewUniform, pixels)),
            ("cap", offset_of!(ViewUniform, cap)),
            ("interior_rule", offset_of!(ViewUniform, interior_rule)),
            ("criterion", offset_of!(ViewUniform, criterion)),
            ("lo", offset_of!(ViewUniform, lo)),
            ("hi", offset_of!(ViewUniform, hi)),
            ("edge_rule", offset_of!(ViewUniform, edge_rule)),
            ("bound", offset_of!(ViewUniform, bound)),
            ("expansion_rows", offset_of!(ViewUniform, expansion_rows)),
        ],
        size_of::<ViewUniform>(),
    );
    assert_same_layout(
        &module,
        "FrameState",
        &[
            ("global_factor", offset_of!(FrameState, global_factor)),
            ("failing", offset_of!(FrameState, failing)),
            ("changed", offset_of!(FrameState, changed)),
            ("done", offset_of!(FrameState, done)),
            ("rounds", offset_of!(FrameState, rounds)),
            ("depth_far", offset_of!(FrameState, depth_far)),
            ("depth_near_complement", offset_of!(FrameState, depth_near_complement)),
        ],
        size_of::<FrameState>(),
    );
    assert_same_layout(
        &module,
        "CheckRow",
        &[
            ("eps", offset_of!(CheckRow, eps)),
            ("bound", offset_of!(CheckRow, bound)),
            ("flags", offset_of!(CheckRow, flags)),
            ("marked", offset_of!(CheckRow, marked)),
        ],
        size_of::<CheckRow>(),
    );
}

#[test]
fn the_codes_the_shaders_compare_against_come_from_rust() {
    let module = cull_module();
    let value = |name: &str| -> u32 {
        let (_, c) = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no constant {name} in the WGSL"));
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref other => panic!("{name} = {other:?}"),
        }
    };
    for (name, rust) in constants()
        .into_iter()
        .filter(|(n, _)| ["INTERIOR_", "CRITERION_", "EDGE_RULE_"].iter().any(|p| n.starts_with(p)))
    {
        assert_eq!(value(name), rust, "{name}");
    }
    // Distinct codes: two rules with one code would be one rule to the shader.
    for prefix in ["INTERIOR_", "CRITERION_", "EDGE_RULE_"] {
        let mut codes: Vec<(&str, u32)> =
            constants().into_iter().filter(|(n, _)| n.starts_with(prefix)).collect();
        let named = codes.len();
        codes.sort_by_key(|&(_, v)| v);
        codes.dedup_by_key(|&mut (_, v)| v);
        assert_eq!(codes.len(), named, "{prefix}: {codes:?}");
        assert!(named >= 3, "{prefix}: {codes:?}");
    }
}
