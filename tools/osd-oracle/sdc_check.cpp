// sdc_check: prints OpenSubdiv's own Catmark refinement masks and child sharpness for a
// seeded table of one-vertex / one-edge neighbourhoods, as the fixture that
// `tessera::subdivision::sdc`'s unit tests compare against
// (crates/tessera/tests/fixtures/sdc/catmark_masks.txt). Build and run with sdc_check.sh.
//
// The neighbourhoods are small stand-ins for the classes Vtr hands to Sdc
// (vtr/componentInterfaces.h): Sdc only asks them for counts and sharpness, so a vertex is
// its sharpness plus the sharpness of its incident edges, and an edge is its sharpness plus
// the sizes of its faces. Masks are computed with double weights, as Bfr's
// Far::PrimvarRefinerReal<double> does; sharpness stays float, as in Sdc.
//
// Output, one case per line, whitespace-separated (Rust parses it token by token):
//
//   vertex METHOD VS N NF ES[N] rules PRULE CRULE child CVS CES[N] atvertex CES[N]
//          w V E[N] F[NF]
//   edge METHOD TRI S NF SIZES[NF] ring0 K0 R0[K0] ring1 K1 R1[K1] child C0 C1
//        crule RULE w V0 V1 F[NF] sdc V0 V1 F[NF]
//   uniform S CHILD
//
// METHOD is `uniform` or `chaikin`, TRI `catmark` or `smooth`, rules are Sdc's names
// (smooth, dart, crease, corner). For vertices the mask is Sdc's with no rule given (Sdc
// derives parent and child rules itself, which is what Vtr's tags amount to). For edges `w`
// is the mask as Vtr asks for it (far/primvarRefiner.h: parent rule crease iff sharpness > 0,
// child rule from how many child edges stay sharp, vtr/refinement.cpp
// reclassifySemisharpVertices) and `sdc` the mask with no rule given; they differ only
// under Chaikin when a sharpness >= 1 decays to zero on one child edge. `ring0`/`ring1` are
// the sharpness of all edges at either end (the edge itself first), used by Chaikin;
// `atvertex` repeats the child edge sharpness with SubdivideEdgeSharpnessAtVertex, edge by
// edge, as vtr/refinement.cpp does. Floats print with enough digits to round-trip.

#include <opensubdiv/sdc/catmarkScheme.h>
#include <opensubdiv/sdc/crease.h>
#include <opensubdiv/sdc/options.h>

#include <cstdint>
#include <cstdio>
#include <vector>

using namespace OpenSubdiv;
using Sdc::Crease;

namespace {

// The Sdc MASK concept with double weights and room for any valence.
struct Mask {
    typedef double Weight;
    std::vector<double> v, e, f;
    int nv = 0, ne = 0, nf = 0;
    bool centers = false;
    explicit Mask(int n) : v(2), e(n), f(n) {}
    int GetNumVertexWeights() const { return nv; }
    int GetNumEdgeWeights() const { return ne; }
    int GetNumFaceWeights() const { return nf; }
    void SetNumVertexWeights(int c) { nv = c; }
    void SetNumEdgeWeights(int c) { ne = c; }
    void SetNumFaceWeights(int c) { nf = c; }
    double const &VertexWeight(int i) const { return v[i]; }
    double const &EdgeWeight(int i) const { return e[i]; }
    double const &FaceWeight(int i) const { return f[i]; }
    double &VertexWeight(int i) { return v[i]; }
    double &EdgeWeight(int i) { return e[i]; }
    double &FaceWeight(int i) { return f[i]; }
    bool AreFaceWeightsForFaceCenters() const { return centers; }
    void SetFaceWeightsForFaceCenters(bool on) { centers = on; }
};

// The Sdc VERTEX concept: a vertex's sharpness and its edges' sharpness.
struct Vertex {
    float sharpness;
    std::vector<float> edges;
    int faces;
    int GetNumEdges() const { return (int)edges.size(); }
    int GetNumFaces() const { return faces; }
    float GetSharpness() const { return sharpness; }
    float *GetSharpnessPerEdge(float s[]) const {
        for (size_t i = 0; i < edges.size(); ++i) s[i] = edges[i];
        return s;
    }
    float GetChildSharpness(Crease const &c) const { return c.SubdivideVertexSharpness(sharpness); }
    float *GetChildSharpnessPerEdge(Crease const &c, float s[]) const {
        c.SubdivideEdgeSharpnessesAroundVertex((int)edges.size(), edges.data(), s);
        return s;
    }
};

// The Sdc EDGE concept: an edge's sharpness, its faces' sizes and its child sharpness.
struct Edge {
    float sharpness;
    std::vector<int> sizes;
    float child[2];
    int GetNumFaces() const { return (int)sizes.size(); }
    float GetSharpness() const { return sharpness; }
    void GetChildSharpnesses(Crease const &, float s[2]) const { s[0] = child[0]; s[1] = child[1]; }
    void GetNumVerticesPerFace(int n[]) const {
        for (size_t i = 0; i < sizes.size(); ++i) n[i] = sizes[i];
    }
};

// A fixed-seed generator, so that the fixture is reproducible.
struct Rng {
    uint64_t s;
    uint32_t next() {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        return (uint32_t)(s >> 33);
    }
    int below(int n) { return (int)(next() % (uint32_t)n); }
    float unit() { return (float)(next() >> 8) / 16777216.0f; }
};

const float kValues[] = {0.0f, 0.2f, 0.5f, 0.9f, 1.0f, 2.8f, 7.9f, 10.0f};

float pick(Rng &r) {
    // Mostly the listed values, sometimes an arbitrary one in [0, 3) or above infinite.
    int k = r.below(12);
    if (k < 8) return kValues[k];
    if (k < 11) return 3.0f * r.unit();
    return 12.5f;
}

const char *ruleName(Crease::Rule r) {
    switch (r) {
    case Crease::RULE_SMOOTH: return "smooth";
    case Crease::RULE_DART: return "dart";
    case Crease::RULE_CREASE: return "crease";
    case Crease::RULE_CORNER: return "corner";
    default: return "unknown";
    }
}

Sdc::Options options(bool chaikin, bool smoothTri) {
    Sdc::Options o;
    o.SetCreasingMethod(chaikin ? Sdc::Options::CREASE_CHAIKIN : Sdc::Options::CREASE_UNIFORM);
    o.SetTriangleSubdivision(smoothTri ? Sdc::Options::TRI_SUB_SMOOTH : Sdc::Options::TRI_SUB_CATMARK);
    return o;
}

void printVertex(bool chaikin, Vertex const &vx) {
    Sdc::Options o = options(chaikin, false);
    Crease crease(o);
    Sdc::Scheme<Sdc::SCHEME_CATMARK> scheme(o);
    int n = vx.GetNumEdges();
    std::vector<float> child(n), at(n);
    vx.GetChildSharpnessPerEdge(crease, child.data());
    for (int i = 0; i < n; ++i) at[i] = crease.SubdivideEdgeSharpnessAtVertex(vx.edges[i], n, vx.edges.data());
    float cvs = vx.GetChildSharpness(crease);
    Crease::Rule pr = crease.DetermineVertexVertexRule(vx.sharpness, n, vx.edges.data());
    Crease::Rule cr = crease.DetermineVertexVertexRule(cvs, n, child.data());
    Mask m(n);
    scheme.ComputeVertexVertexMask(vx, m);

    std::printf("vertex %s %.9g %d %d", chaikin ? "chaikin" : "uniform", vx.sharpness, n, vx.faces);
    for (float s : vx.edges) std::printf(" %.9g", s);
    std::printf(" rules %s %s child %.9g", ruleName(pr), ruleName(cr), cvs);
    for (float s : child) std::printf(" %.9g", s);
    std::printf(" atvertex");
    for (float s : at) std::printf(" %.9g", s);
    // Sparse masks (e.g. a corner's) have no edge or face weights: print them as zeros.
    std::printf(" w %.17g", m.v[0]);
    for (int i = 0; i < n; ++i) std::printf(" %.17g", i < m.ne ? m.e[i] : 0.0);
    for (int i = 0; i < vx.faces; ++i) std::printf(" %.17g", i < m.nf ? m.f[i] : 0.0);
    std::printf("\n");
}

std::vector<float> ring(Rng &r, float self) {
    std::vector<float> s(2 + r.below(5));
    s[0] = self;
    for (size_t i = 1; i < s.size(); ++i) s[i] = r.below(2) ? pick(r) : 0.0f;
    return s;
}

void printEdge(bool chaikin, bool smoothTri, float sharp, std::vector<int> const &sizes,
               std::vector<float> const &r0, std::vector<float> const &r1) {
    Sdc::Options o = options(chaikin, smoothTri);
    Crease crease(o);
    Sdc::Scheme<Sdc::SCHEME_CATMARK> scheme(o);
    Edge e{sharp, sizes, {0, 0}};
    // vtr/refinement.cpp subdivideEdgeSharpness: each child edge from its end's ring.
    e.child[0] = crease.SubdivideEdgeSharpnessAtVertex(sharp, (int)r0.size(), r0.data());
    e.child[1] = crease.SubdivideEdgeSharpnessAtVertex(sharp, (int)r1.size(), r1.data());

    // The rules Vtr passes (far/primvarRefiner.h, vtr/refinement.cpp).
    Crease::Rule pRule = sharp > 0.0f ? Crease::RULE_CREASE : Crease::RULE_SMOOTH;
    Crease::Rule cRule = Crease::RULE_SMOOTH;
    if (Crease::IsInfinite(sharp)) {
        cRule = Crease::RULE_CREASE;
    } else if (Crease::IsSharp(sharp)) {
        cRule = crease.DetermineVertexVertexRule(0.0f, Crease::IsSharp(e.child[0]) + Crease::IsSharp(e.child[1]));
    }
    int nf = (int)sizes.size();
    Mask vtr(nf), sdc(nf);
    scheme.ComputeEdgeVertexMask(e, vtr, pRule, cRule);
    scheme.ComputeEdgeVertexMask(e, sdc);

    std::printf("edge %s %s %.9g %d", chaikin ? "chaikin" : "uniform", smoothTri ? "smooth" : "catmark", sharp, nf);
    for (int s : sizes) std::printf(" %d", s);
    std::printf(" ring0 %d", (int)r0.size());
    for (float s : r0) std::printf(" %.9g", s);
    std::printf(" ring1 %d", (int)r1.size());
    for (float s : r1) std::printf(" %.9g", s);
    std::printf(" child %.9g %.9g crule %s", e.child[0], e.child[1], ruleName(cRule));
    for (Mask const *m : {&vtr, &sdc}) {
        std::printf(m == &vtr ? " w" : " sdc");
        std::printf(" %.17g %.17g", m->v[0], m->v[1]);
        for (int i = 0; i < nf; ++i) std::printf(" %.17g", i < m->nf ? m->f[i] : 0.0);
    }
    std::printf("\n");
}

}  // namespace

int main() {
    Rng r{20240603};
    std::printf("# OpenSubdiv v%d.%d.%d Sdc Catmark masks, printed by tools/osd-oracle/sdc_check.cpp (seed 20240603); regenerate with tools/osd-oracle/sdc_check.sh\n",
                OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR, OPENSUBDIV_VERSION_PATCH);

    // Vertices: valences 2-7, interior (N faces) and boundary (N-1 faces, the first and
    // last edge on the boundary, so infinitely sharp as Far makes them), uniform and Chaikin.
    for (int chaikin = 0; chaikin < 2; ++chaikin) {
        for (int n = 2; n <= 7; ++n) {
            for (int boundary = 0; boundary < 2; ++boundary) {
                for (int k = 0; k < 40; ++k) {
                    Vertex vx{0.0f, std::vector<float>(n, 0.0f), boundary ? n - 1 : n};
                    // Every listed sharpness on a single edge and on the vertex, then mixtures.
                    if (k < 8) {
                        vx.edges[boundary ? n / 2 : 0] = kValues[k];
                    } else if (k < 16) {
                        vx.sharpness = kValues[k - 8];
                    } else {
                        int odds = 1 + r.below(3);  // how sharp this case is
                        for (float &s : vx.edges) s = r.below(4) < odds ? pick(r) : 0.0f;
                        vx.sharpness = r.below(5) == 0 ? pick(r) : 0.0f;
                    }
                    if (boundary) vx.edges.front() = vx.edges.back() = Crease::SHARPNESS_INFINITE;
                    printVertex(chaikin, vx);
                }
            }
        }
    }

    // Edges: two quads, a triangle on either or both sides, a pentagon, one face (a boundary
    // edge left smooth, which Far never does but Sdc defines) and three faces (non-manifold).
    const std::vector<std::vector<int>> faceSets = {{4, 4}, {3, 4}, {4, 3}, {3, 3}, {5, 4}, {4}, {4, 4, 4}, {3, 4, 3}};
    for (int chaikin = 0; chaikin < 2; ++chaikin) {
        for (int tri = 0; tri < 2; ++tri) {
            for (auto const &sizes : faceSets) {
                for (float s : kValues) printEdge(chaikin, tri, s, sizes, ring(r, s), ring(r, s));
                for (int k = 0; k < 8; ++k) {
                    float s = pick(r);
                    printEdge(chaikin, tri, s, sizes, ring(r, s), ring(r, s));
                }
            }
        }
    }
    // Chaikin decaying a sharpness in [1, 4/3) to zero on one or both child edges: Vtr's
    // rules then blend with the unclamped sharpness (weights outside [0, 1]) where Sdc
    // alone would choose the crease mask.
    for (float s : {1.0f, 1.2f, 1.3f}) {
        for (auto const &other : {std::vector<float>{0.2f}, std::vector<float>{2.8f}, std::vector<float>{0.5f, 10.0f}}) {
            std::vector<float> r0{s, 0.2f, 0.0f}, r1{s};
            r1.insert(r1.end(), other.begin(), other.end());
            printEdge(true, false, s, {4, 4}, r0, r1);
            printEdge(true, true, s, {3, 4}, r1, r0);
        }
    }

    // Uniform decrement of single values (SubdivideUniformSharpness).
    Crease uniform(options(false, false));
    for (float s : kValues) std::printf("uniform %.9g %.9g\n", s, uniform.SubdivideUniformSharpness(s));
    for (float s : {0.001f, 1.0001f, 1.5f, 9.99f, 12.5f, 3.0f * r.unit()}) {
        std::printf("uniform %.9g %.9g\n", s, uniform.SubdivideUniformSharpness(s));
    }
    return 0;
}
