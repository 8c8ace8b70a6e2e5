// Invocations per workgroup of the element-parallel passes (`shader::WORKGROUP`).
const WORKGROUP: u32 = {{WORKGROUP}}u;

// The invocation's index in a dispatch laid out by `shader::grid` (2D past 65,535 groups):
// every element-parallel pass numbers its invocations by this one rule.
fn thread_index(wid: vec3<u32>, nwg: vec3<u32>, lid: u32) -> u32 {
    return (wid.y * nwg.x + wid.x) * WORKGROUP + lid;
}
