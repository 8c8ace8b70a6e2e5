// Loop Gregory-triangle end-cap oracle: prints, for small built-in Loop cages, every
// GREGORY_TRIANGLE patch that OpenSubdiv's Far::LoopPatchBuilder makes -- its source patch
// (corner flags and rings as indices into the patch's source points, in Far::SourcePatch's
// order) and the 18 x N conversion matrix -- for tessera's subdivision::loop_gregory test.
//
// Patches are found and converted with Far::PatchBuilder under Bfr's options
// (bfr/patchTreeBuilder.cpp: useInfSharpPatch, no smooth-corner approximation, Gregory
// irregular basis), the matrix in double. Cages are either left unrefined (every irregular
// base face is then a leaf, so one patch may have several irregular corners next to each
// other) or refined adaptively to level 1 or 2 (one irregular corner among regular ones).
// As a check on that route, each refined cage also goes through Far::PatchTableFactory with
// ENDCAP_GREGORY_BASIS (double precision): every builder patch, applied to the refined
// positions, must reappear among the table's GREGORY_TRIANGLE patches; the largest
// difference is printed to stderr and the program fails if it exceeds 1e-12.
//
// Output (stdout), after '#' header lines, one block per distinct patch (a patch whose source
// patch and matrix equal an earlier one's is left out):
//   patch CAGE LEVEL FACE NUMSOURCE
//   corner NUMFACES PATCHFACE BOUNDARY SHARP DART   (3 lines, corners in order; corner i is
//   ring N I0 I1 ...                                 source point i; a ring after each corner)
//   row N COL W COL W ...                            (18 lines, the matrix rows in order)
#include <opensubdiv/far/loopPatchBuilder.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/version.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace OpenSubdiv;
using Far::Index;

struct P3 {
    double x = 0, y = 0, z = 0;
    void Clear(void * = nullptr) { x = y = z = 0; }
    void AddWithWeight(P3 const &p, double w) { x += w * p.x; y += w * p.y; z += w * p.z; }
};

struct Cage {
    std::string name;
    std::vector<P3> pos;
    std::vector<int> tris;
    Sdc::Options::VtxBoundaryInterpolation boundary = Sdc::Options::VTX_BOUNDARY_EDGE_ONLY;
    std::vector<int> corners;  // infinitely sharp vertices
    std::vector<int> creases;  // vertex pairs of infinitely sharp edges
    int level = 2;             // adaptive isolation level; 0 leaves the cage unrefined
};

// Makes the builder's source-patch assembly, which Far keeps protected, reachable.
struct Probe : Far::LoopPatchBuilder {
    Probe(Far::TopologyRefiner const &r, Options const &o) : Far::LoopPatchBuilder(r, o) {}
    using Far::PatchBuilder::assembleIrregularSourcePatch;
};

// A deterministic jitter so that no configuration is accidentally symmetric.
static double jitter(int i, int k) { return 0.1 * std::sin(12.9898 * i + 78.233 * k + 1.0); }

static void jitterAll(Cage &c) {
    for (size_t i = 0; i < c.pos.size(); ++i) {
        c.pos[i].x += jitter(i, 0);
        c.pos[i].y += jitter(i, 1);
        c.pos[i].z += 0.3 * jitter(i, 2);
    }
}

// n triangular sectors of side k around vertex 0 (each cut into k*k triangles), closed
// (vertex 0 interior of valence n) or open (vertex 0 on the boundary with n faces).
// spoke(j, a) is the vertex a steps out along spoke j.
struct Fan {
    int n, k, spokes;
    int g(int j, int a, int b) const {  // a steps along spoke j, b along spoke j+1
        if (a == 0 && b == 0) return 0;
        if (b == 0) return 1 + j * k + (a - 1);
        if (a == 0) return 1 + ((j + 1) % spokes) * k + (b - 1);
        // strictly inside sector j: a, b >= 1 and a + b <= k
        int idx = 0;
        for (int aa = 1; aa < a; ++aa) idx += k - aa;
        return 1 + spokes * k + j * (k * (k - 1) / 2) + idx + (b - 1);
    }
};

// rot turns every triangle's vertex list, so that an unrefined fan's centre is corner rot of
// its triangles (refinement picks its own order).
static Cage fan(std::string name, int n, int k, bool closed, int level = 2, int rot = 0) {
    Cage c;
    c.name = name;
    c.level = level;
    Fan f{n, k, closed ? n : n + 1};
    c.pos.resize(1 + f.spokes * k + n * (k * (k - 1) / 2));
    double step = (closed ? 2.0 : 1.0) * M_PI / n;
    for (int j = 0; j < n; ++j)
        for (int a = 0; a <= k; ++a)
            for (int b = 0; a + b <= k; ++b) {
                P3 &p = c.pos[f.g(j, a, b)];
                p.x = a * std::cos(step * j) + b * std::cos(step * (j + 1));
                p.y = a * std::sin(step * j) + b * std::sin(step * (j + 1));
            }
    for (int j = 0; j < n; ++j)
        for (int a = 0; a < k; ++a)
            for (int b = 0; a + b < k; ++b) {
                int t[3] = {f.g(j, a, b), f.g(j, a + 1, b), f.g(j, a, b + 1)};
                std::rotate(t, t + (3 - rot) % 3, t + 3);
                c.tris.insert(c.tris.end(), t, t + 3);
                if (a + b + 2 <= k) {
                    int u[3] = {f.g(j, a + 1, b), f.g(j, a + 1, b + 1), f.g(j, a, b + 1)};
                    std::rotate(u, u + (3 - rot) % 3, u + 3);
                    c.tris.insert(c.tris.end(), u, u + 3);
                }
            }
    jitterAll(c);
    return c;
}

// The infinitely sharp edges along spoke j of a fan, from the centre outwards.
static void creaseSpoke(Cage &c, int n, int k, bool closed, int j) {
    Fan f{n, k, closed ? n : n + 1};
    for (int a = 0; a < k; ++a) {
        c.creases.push_back(f.g(j % f.spokes, a, 0));
        c.creases.push_back(f.g(j % f.spokes, a + 1, 0));
    }
}

static Cage octahedron() {
    Cage c;
    c.name = "octahedron";
    c.level = 0;
    double v[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (auto &p : v) c.pos.push_back(P3{p[0], p[1], p[2]});
    int t[] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    c.tris.assign(t, t + 24);
    jitterAll(c);
    return c;
}

static Cage icosahedron() {
    Cage c;
    c.name = "icosahedron";
    c.level = 0;
    double g = (1 + std::sqrt(5.0)) / 2;
    double v[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                       {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    for (auto &p : v) c.pos.push_back(P3{p[0], p[1], p[2]});
    int t[] = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
               3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
    c.tris.assign(t, t + 60);
    jitterAll(c);
    return c;
}

// Two triangles on the same three vertices: every vertex is an interior vertex of valence 2.
static Cage pillow(int level) {
    Cage c;
    c.name = "pillow";
    c.level = level;
    double v[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    for (auto &p : v) c.pos.push_back(P3{p[0], p[1], p[2]});
    int t[] = {0, 1, 2, 0, 2, 1};
    c.tris.assign(t, t + 6);
    jitterAll(c);
    return c;
}

static std::string rowText(Far::SparseMatrix<double> const &m, int row) {
    auto cols = m.GetRowColumns(row);
    auto w = m.GetRowElements(row);
    std::string s = "row " + std::to_string(m.GetRowSize(row));
    char buf[48];
    for (int e = 0; e < m.GetRowSize(row); ++e) {
        std::snprintf(buf, sizeof buf, " %d %.17g", cols[e], w[e]);
        s += buf;
    }
    return s + "\n";
}

static int numPatches = 0;
static std::vector<std::string> printed;  // blocks already written

static double run(Cage const &cage) {
    typedef Far::TopologyDescriptor Desc;
    int nf = (int)cage.tris.size() / 3;
    std::vector<int> counts(nf, 3);
    std::vector<float> cornerWeights(cage.corners.size(), Sdc::Crease::SHARPNESS_INFINITE);
    std::vector<float> creaseWeights(cage.creases.size() / 2, Sdc::Crease::SHARPNESS_INFINITE);
    Desc desc;
    desc.numVertices = (int)cage.pos.size();
    desc.numFaces = nf;
    desc.numVertsPerFace = counts.data();
    desc.vertIndicesPerFace = cage.tris.data();
    desc.numCorners = (int)cage.corners.size();
    desc.cornerVertexIndices = cage.corners.data();
    desc.cornerWeights = cornerWeights.data();
    desc.numCreases = (int)creaseWeights.size();
    desc.creaseVertexIndexPairs = cage.creases.data();
    desc.creaseWeights = creaseWeights.data();
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(cage.boundary);
    Far::TopologyRefiner *refiner = Far::TopologyRefinerFactory<Desc>::Create(
        desc, Far::TopologyRefinerFactory<Desc>::Options(Sdc::SCHEME_LOOP, sdc));

    if (cage.level > 0) {
        Far::TopologyRefiner::AdaptiveOptions adaptive(cage.level);
        adaptive.useInfSharpPatch = true;
        adaptive.useSingleCreasePatch = false;
        refiner->RefineAdaptive(adaptive);
    }

    int nLevels = refiner->GetNumLevels();
    std::vector<int> offset(nLevels + 1, 0);
    for (int l = 0; l < nLevels; ++l) offset[l + 1] = offset[l] + refiner->GetLevel(l).GetNumVertices();
    std::vector<P3> all(offset[nLevels]);
    std::copy(cage.pos.begin(), cage.pos.end(), all.begin());
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    for (int l = 1; l < nLevels; ++l) {
        P3 const *from = &all[offset[l - 1]];
        P3 *to = &all[offset[l]];
        primvar.Interpolate(l, from, to);
    }

    Far::PatchBuilder::Options options;
    options.regBasisType = Far::PatchBuilder::BASIS_REGULAR;
    options.irregBasisType = Far::PatchBuilder::BASIS_GREGORY;
    options.approxInfSharpWithSmooth = false;
    options.approxSmoothCornerWithSharp = false;
    options.fillMissingBoundaryPoints = true;
    Probe builder(*refiner, options);

    std::vector<std::vector<P3>> builderPatches;
    for (int l = 0; l < nLevels; ++l) {
        P3 const *lp = &all[offset[l]];
        for (Index f = 0; f < refiner->GetLevel(l).GetNumFaces(); ++f) {
            if (!builder.IsFaceAPatch(l, f) || !builder.IsFaceALeaf(l, f) || builder.IsPatchRegular(l, f))
                continue;
            Vtr::internal::Level::VSpan spans[4];
            builder.GetIrregularPatchCornerSpans(l, f, spans);
            Far::SourcePatch sp;
            builder.assembleIrregularSourcePatch(l, f, spans, sp);
            std::vector<Index> src(sp.GetNumSourcePoints());
            builder.GetIrregularPatchSourcePoints(l, f, spans, src.data());
            Far::SparseMatrix<double> m;
            builder.GetIrregularPatchConversionMatrix(l, f, spans, m);
            if (m.GetNumRows() != 18 || m.GetNumColumns() != sp.GetNumSourcePoints()) {
                std::fprintf(stderr, "%s %d %d: unexpected %d x %d matrix\n", cage.name.c_str(), l, f,
                             m.GetNumRows(), m.GetNumColumns());
                std::exit(2);
            }

            // The matrix depends only on the topology, so a block already printed for another
            // face (by symmetry of the cages, most of them) is not printed again.
            std::string body;
            char buf[64];
            for (int c = 0; c < 3; ++c) {
                Far::SourcePatch::Corner const &sc = sp._corners[c];
                std::snprintf(buf, sizeof buf, "corner %d %d %d %d %d\n", sc._numFaces, sc._patchFace,
                              sc._boundary, sc._sharp, sc._dart);
                body += buf;
                std::vector<int> ring(sp.GetCornerRingSize(c));
                sp.GetCornerRingPoints(c, ring.data());
                body += "ring " + std::to_string(ring.size());
                for (int r : ring) body += " " + std::to_string(r);
                body += "\n";
            }
            for (int row = 0; row < 18; ++row) body += rowText(m, row);
            if (std::find(printed.begin(), printed.end(), body) == printed.end()) {
                printed.push_back(body);
                std::printf("patch %s %d %d %d\n%s", cage.name.c_str(), l, f, sp.GetNumSourcePoints(),
                            body.c_str());
            }
            std::vector<P3> pts(18);
            for (int row = 0; row < 18; ++row) {
                auto cols = m.GetRowColumns(row);
                auto w = m.GetRowElements(row);
                for (int e = 0; e < m.GetRowSize(row); ++e) pts[row].AddWithWeight(lp[src[cols[e]]], w[e]);
            }
            builderPatches.push_back(pts);
            ++numPatches;
        }
    }

    double worst = 0;
    size_t numTable = 0;
    if (cage.level > 0) {
        Far::PatchTableFactory::Options tableOptions(cage.level);
        tableOptions.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
        tableOptions.SetPatchPrecision<double>();
        tableOptions.useInfSharpPatch = true;
        tableOptions.generateLegacySharpCornerPatches = false;
        Far::PatchTable *table = Far::PatchTableFactory::Create(*refiner, tableOptions);
        Far::StencilTableReal<double> const *stencils = table->GetLocalPointStencilTable<double>();
        std::vector<P3> local(table->GetNumLocalPoints());
        if (stencils && !local.empty()) stencils->UpdateValues(all.data(), local.data());
        std::vector<std::vector<P3>> tablePatches;
        for (int a = 0; a < table->GetNumPatchArrays(); ++a) {
            if (table->GetPatchArrayDescriptor(a).GetType() != Far::PatchDescriptor::GREGORY_TRIANGLE) continue;
            for (int p = 0; p < table->GetNumPatches(a); ++p) {
                auto cvs = table->GetPatchVertices(a, p);
                std::vector<P3> pts;
                for (int k = 0; k < cvs.size(); ++k)
                    pts.push_back(cvs[k] < (int)all.size() ? all[cvs[k]] : local[cvs[k] - all.size()]);
                tablePatches.push_back(pts);
            }
        }
        numTable = tablePatches.size();
        auto diff = [](std::vector<P3> const &a, std::vector<P3> const &b) {
            double d = 0;
            for (size_t i = 0; i < a.size(); ++i)
                d = std::max(d, std::max(std::fabs(a[i].x - b[i].x),
                                         std::max(std::fabs(a[i].y - b[i].y), std::fabs(a[i].z - b[i].z))));
            return d;
        };
        for (auto const &bp : builderPatches) {
            double best = 1e300;
            for (auto const &tp : tablePatches) best = std::min(best, diff(bp, tp));
            worst = std::max(worst, best);
        }
        delete table;
    }
    std::fprintf(stderr, "%s (level %d): %zu builder patches, %zu table Gregory triangles, max difference %.3g\n",
                 cage.name.c_str(), cage.level, builderPatches.size(), numTable, worst);
    delete refiner;
    return worst;
}

int main() {
    std::vector<Cage> cages;
    // Interior irregular corners of valence 3..12 among regular neighbours.
    for (int n = 3; n <= 12; ++n) {
        if (n == 6) continue;
        cages.push_back(fan("fan" + std::to_string(n), n, 2, true));
    }
    // Smooth boundary corners of 1 (edge-only: a smooth one-face corner), 2, 4 and 5 faces.
    for (int n : {1, 2, 4, 5}) cages.push_back(fan("open" + std::to_string(n), n, 2, false));
    // The same rims with sharp corners (edge-and-corner), and a sharp one-face corner.
    for (int n : {1, 2, 4}) {
        Cage c = fan("open" + std::to_string(n) + "_corners", n, 2, false);
        c.boundary = Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER;
        cages.push_back(c);
    }
    // Sharp interior and boundary vertices (corner tags).
    Cage corner5 = fan("fan5_corner", 5, 2, true);
    corner5.corners.push_back(0);
    cages.push_back(corner5);
    Cage corner3 = fan("open3_corner", 3, 2, false);
    corner3.corners.push_back(0);
    cages.push_back(corner3);
    // A dart: one infinitely sharp spoke ending inside.
    Cage dart = fan("fan5_dart", 5, 3, true);
    creaseSpoke(dart, 5, 3, true, 0);
    cages.push_back(dart);
    // A simple crease through an irregular vertex (corner spans of 3 and 4 faces, smooth).
    Cage crease = fan("fan7_crease", 7, 2, true);
    creaseSpoke(crease, 7, 2, true, 0);
    creaseSpoke(crease, 7, 2, true, 3);
    cages.push_back(crease);
    // Three sharp spokes: spans of 2, 2 and 1 faces, sharp.
    Cage spokes = fan("fan5_three_creases", 5, 2, true);
    for (int j : {0, 2, 4}) creaseSpoke(spokes, 5, 2, true, j);
    cages.push_back(spokes);
    // A regular vertex with a crease across it (spans of 3 faces on each side).
    Cage reg = fan("fan6_crease", 6, 2, true);
    creaseSpoke(reg, 6, 2, true, 1);
    creaseSpoke(reg, 6, 2, true, 4);
    cages.push_back(reg);
    // Valence-2 interior vertices.
    // (Unrefined, OpenSubdiv's builder cannot take the pillow: every source point is a corner.)
    cages.push_back(pillow(2));
    // Unrefined cages: several irregular (and regular) corners in one patch.
    cages.push_back(octahedron());
    cages.push_back(icosahedron());
    for (int n : {4, 5, 7}) cages.push_back(fan("fan" + std::to_string(n) + "_base", n, 2, true, 0));
    cages.push_back(fan("fan6_base", 6, 3, true, 0));
    cages.push_back(fan("open4_base", 4, 2, false, 0));
    Cage open3b = fan("open3_base_corners", 3, 2, false, 0);
    open3b.boundary = Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER;
    cages.push_back(open3b);
    Cage crease5b = fan("fan5_base_crease", 5, 2, true, 0);
    creaseSpoke(crease5b, 5, 2, true, 0);
    creaseSpoke(crease5b, 5, 2, true, 2);
    cages.push_back(crease5b);
    Cage dart6b = fan("fan6_base_dart", 6, 3, true, 0);
    creaseSpoke(dart6b, 6, 3, true, 0);
    cages.push_back(dart6b);
    Cage corner5b = fan("fan5_base_corner", 5, 2, true, 0);
    corner5b.corners.push_back(0);
    cages.push_back(corner5b);
    // An unrefined valence-3 centre as each corner of its triangles (a neighbour without
    // points of its own in the source patch), and two adjacent sharp corners (face-point
    // corrections outside the points of P and E are dropped).
    for (int rot = 0; rot < 3; ++rot) {
        cages.push_back(fan("fan3_base_rot" + std::to_string(rot), 3, 2, true, 0, rot));
        Cage two = fan("fan5_base_two_corners_rot" + std::to_string(rot), 5, 2, true, 0, rot);
        two.corners = {0, 1};
        cages.push_back(two);
    }
    Cage ico2 = icosahedron();
    ico2.name = "icosahedron_two_corners";
    ico2.corners = {0, 1};
    cages.push_back(ico2);
    // Irregular corners at isolation level 1.
    cages.push_back(fan("fan5_level1", 5, 2, true, 1));
    cages.push_back(fan("open2_level1", 2, 2, false, 1));

    std::printf("# GREGORY_TRIANGLE conversion matrices of OpenSubdiv %d.%d.%d's Far::LoopPatchBuilder (Bfr's options),\n",
                OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR, OPENSUBDIV_VERSION_PATCH);
    std::printf("# written by tools/osd-oracle/loop_gregory_check.sh from loop_gregory_check.cpp; do not edit.\n");
    double worst = 0;
    for (auto const &c : cages) worst = std::max(worst, run(c));
    std::fprintf(stderr, "%d patches (%zu distinct), worst builder-table difference %.3g\n", numPatches, printed.size(), worst);
    return worst < 1e-12 ? 0 : 1;
}
