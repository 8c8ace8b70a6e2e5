// loop_sdc_check: prints OpenSubdiv's own Loop refinement and limit masks for a seeded table
// of one-vertex / one-edge neighbourhoods, as the fixture that
// `tessera::subdivision::loop_sdc`'s unit tests compare against
// (crates/tessera/tests/fixtures/sdc/loop_masks.txt). Build and run with loop_sdc_check.sh.
//
// It is sdc_check.cpp's companion for Sdc::Scheme<SCHEME_LOOP>: the same stand-ins for the
// neighbourhoods Vtr hands to Sdc (counts and sharpness only; for limit masks the position
// of an edge in the list matters, and the list is taken to be in Vtr's order:
// counter-clockwise, a boundary vertex's list starting at its leading boundary edge), the
// same double weights as Far::PrimvarRefinerReal<double>, the same float sharpness.
//
// Output, one case per line, whitespace-separated (Rust parses it token by token):
//
//   vertex METHOD VS N NF ES[N] rules PRULE CRULE w V E[N]
//   edge METHOD S NF ring0 K0 R0[K0] ring1 K1 R1[K1] child C0 C1 crule RULE
//        w V0 V1 F[NF] sdc V0 V1 F[NF]
//   limit RULE N NF ES[N] pos V E[N] tan1 V E[N] tan2 V E[N]
//
// METHOD is `uniform` or `chaikin`; rules are Sdc's names (smooth, dart, crease, corner).
// Vertex masks are Sdc's with no rule given (Sdc derives parent and child rules itself, as
// Vtr's tags amount to). Edge masks: `w` with the rules Vtr passes (far/primvarRefiner.h),
// `sdc` with none, as in sdc_check.cpp; the face weights are Far's reading of them, the
// vertex of each incident triangle opposite the edge. Limit masks take the rule the caller
// gives (Far passes the vertex's rule at the last level): here the rule Sdc determines from
// VS and ES, so every rule occurs with the sharpness that makes it. Sparse weights (a
// corner's missing edges) print as zeros. Floats print with enough digits to round-trip.

#include <opensubdiv/sdc/crease.h>
#include <opensubdiv/sdc/loopScheme.h>
#include <opensubdiv/sdc/options.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <vector>

using namespace OpenSubdiv;
using Sdc::Crease;

namespace {

// The Sdc MASK concept with double weights. Room for at least two edges: Loop's corner
// tangent masks write the second edge weight even at a vertex with one edge.
struct Mask {
    typedef double Weight;
    std::vector<double> v, e, f;
    int nv = 0, ne = 0, nf = 0;
    bool centers = false;
    explicit Mask(int n) : v(2), e(std::max(n, 2)), f(std::max(n, 2)) {}
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

// The Sdc VERTEX concept: a vertex's sharpness and its edges' sharpness, in order.
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

// The Sdc EDGE concept: an edge's sharpness, its face count and its child sharpness.
struct Edge {
    float sharpness;
    int faces;
    float child[2];
    int GetNumFaces() const { return faces; }
    float GetSharpness() const { return sharpness; }
    void GetChildSharpnesses(Crease const &, float s[2]) const { s[0] = child[0]; s[1] = child[1]; }
    void GetNumVerticesPerFace(int n[]) const {
        for (int i = 0; i < faces; ++i) n[i] = 3;
    }
};

// The fixed-seed generator of sdc_check.cpp, so that the fixture is reproducible.
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

Sdc::Options options(bool chaikin) {
    Sdc::Options o;
    o.SetCreasingMethod(chaikin ? Sdc::Options::CREASE_CHAIKIN : Sdc::Options::CREASE_UNIFORM);
    return o;
}

void printWeights(char const *label, Mask const &m, int n) {
    std::printf(" %s %.17g", label, m.nv ? m.v[0] : 0.0);
    for (int i = 0; i < n; ++i) std::printf(" %.17g", i < m.ne ? m.e[i] : 0.0);
}

void printVertex(bool chaikin, Vertex const &vx) {
    Sdc::Options o = options(chaikin);
    Crease crease(o);
    Sdc::Scheme<Sdc::SCHEME_LOOP> scheme(o);
    int n = vx.GetNumEdges();
    std::vector<float> child(n);
    vx.GetChildSharpnessPerEdge(crease, child.data());
    float cvs = vx.GetChildSharpness(crease);
    Crease::Rule pr = crease.DetermineVertexVertexRule(vx.sharpness, n, vx.edges.data());
    Crease::Rule cr = crease.DetermineVertexVertexRule(cvs, n, child.data());
    Mask m(n);
    scheme.ComputeVertexVertexMask(vx, m);

    std::printf("vertex %s %.9g %d %d", chaikin ? "chaikin" : "uniform", vx.sharpness, n, vx.faces);
    for (float s : vx.edges) std::printf(" %.9g", s);
    std::printf(" rules %s %s", ruleName(pr), ruleName(cr));
    printWeights("w", m, n);
    std::printf("\n");

    // The limit masks of the same neighbourhood with the rule of its sharpness.
    Mask pos(n), tan1(n), tan2(n);
    scheme.ComputeVertexLimitMask(vx, pos, tan1, tan2, pr);
    std::printf("limit %s %d %d", ruleName(pr), n, vx.faces);
    for (float s : vx.edges) std::printf(" %.9g", s);
    printWeights("pos", pos, n);
    printWeights("tan1", tan1, n);
    printWeights("tan2", tan2, n);
    std::printf("\n");
}

std::vector<float> ring(Rng &r, float self) {
    std::vector<float> s(2 + r.below(5));
    s[0] = self;
    for (size_t i = 1; i < s.size(); ++i) s[i] = r.below(2) ? pick(r) : 0.0f;
    return s;
}

void printEdge(bool chaikin, float sharp, int faces, std::vector<float> const &r0,
               std::vector<float> const &r1) {
    Sdc::Options o = options(chaikin);
    Crease crease(o);
    Sdc::Scheme<Sdc::SCHEME_LOOP> scheme(o);
    Edge e{sharp, faces, {0, 0}};
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
    Mask vtr(faces), sdc(faces);
    scheme.ComputeEdgeVertexMask(e, vtr, pRule, cRule);
    scheme.ComputeEdgeVertexMask(e, sdc);

    std::printf("edge %s %.9g %d", chaikin ? "chaikin" : "uniform", sharp, faces);
    std::printf(" ring0 %d", (int)r0.size());
    for (float s : r0) std::printf(" %.9g", s);
    std::printf(" ring1 %d", (int)r1.size());
    for (float s : r1) std::printf(" %.9g", s);
    std::printf(" child %.9g %.9g crule %s", e.child[0], e.child[1], ruleName(cRule));
    for (Mask const *m : {&vtr, &sdc}) {
        std::printf(m == &vtr ? " w" : " sdc");
        std::printf(" %.17g %.17g", m->v[0], m->v[1]);
        for (int i = 0; i < faces; ++i) std::printf(" %.17g", i < m->nf ? m->f[i] : 0.0);
    }
    std::printf("\n");
}

}  // namespace

int main() {
    Rng r{20241204};
    std::printf("# OpenSubdiv v%d.%d.%d Sdc Loop refinement and limit masks, printed by tools/osd-oracle/loop_sdc_check.cpp (seed 20241204); regenerate with tools/osd-oracle/loop_sdc_check.sh\n",
                OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR, OPENSUBDIV_VERSION_PATCH);

    // Vertices (each followed by its limit masks): valences 1-12, interior (N faces) and
    // boundary (N-1 faces, N >= 2, the first and last edge on the boundary, so infinitely
    // sharp as Far makes them), uniform and Chaikin.
    for (int chaikin = 0; chaikin < 2; ++chaikin) {
        for (int n = 1; n <= 12; ++n) {
            for (int boundary = 0; boundary < 2; ++boundary) {
                if (boundary && n < 2) continue;
                for (int k = 0; k < 32; ++k) {
                    Vertex vx{0.0f, std::vector<float>(n, 0.0f), boundary ? n - 1 : n};
                    if (k < 8) {
                        // Every listed sharpness on a single edge...
                        vx.edges[boundary ? n / 2 : 0] = kValues[k];
                    } else if (k < 16) {
                        // ... on the vertex ...
                        vx.sharpness = kValues[k - 8];
                    } else if (k < 22 && n >= 2) {
                        // ... on an interior crease through two random edges (a crease's ends
                        // anywhere in the list, for the order-dependent tangent masks) ...
                        int a = r.below(n), b = r.below(n - 1);
                        if (b >= a) ++b;
                        vx.edges[a] = pick(r);
                        vx.edges[b] = kValues[4 + r.below(4)];
                    } else {
                        // ... then mixtures: up to three sharp edges anywhere (so that
                        // high valences are not all corners), sometimes a sharp vertex.
                        for (int c = r.below(4); c > 0; --c) vx.edges[r.below(n)] = pick(r);
                        vx.sharpness = r.below(6) == 0 ? pick(r) : 0.0f;
                    }
                    if (boundary) vx.edges.front() = vx.edges.back() = Crease::SHARPNESS_INFINITE;
                    printVertex(chaikin, vx);
                }
            }
        }
    }

    // Edges: two triangles, one (a boundary edge left smooth, which Far never does but Sdc
    // defines), three and four (non-manifold).
    for (int chaikin = 0; chaikin < 2; ++chaikin) {
        for (int faces : {2, 1, 3, 4}) {
            for (float s : kValues) printEdge(chaikin, s, faces, ring(r, s), ring(r, s));
            for (int k = 0; k < 12; ++k) {
                float s = pick(r);
                printEdge(chaikin, s, faces, ring(r, s), ring(r, s));
            }
        }
    }
    // Chaikin decaying a sharpness in [1, 4/3) to zero on one or both child edges: Vtr's
    // rules then blend with the unclamped sharpness where Sdc alone would choose the crease.
    for (float s : {1.0f, 1.2f, 1.3f}) {
        for (auto const &other : {std::vector<float>{0.2f}, std::vector<float>{2.8f}, std::vector<float>{0.5f, 10.0f}}) {
            std::vector<float> r0{s, 0.2f, 0.0f}, r1{s};
            r1.insert(r1.end(), other.begin(), other.end());
            printEdge(true, s, 2, r0, r1);
            printEdge(true, s, 2, r1, r0);
        }
    }
    return 0;
}
