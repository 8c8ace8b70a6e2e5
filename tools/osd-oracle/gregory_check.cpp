// Gregory end-cap oracle: prints, for small built-in cages, every Gregory basis patch that
// OpenSubdiv builds at isolation level 2 -- its source patch (corner flags and rings, in
// Far::SourcePatch's order) and its 20 points -- for tessera's subdivision::gregory test.
//
// The patches are found and converted with Far::PatchBuilder under Bfr's options
// (bfr/patchTreeBuilder.cpp: useInfSharpPatch, no smooth-corner approximation, Gregory
// irregular basis), the conversion matrix in double. As a check on that route, the same cage
// also goes through Far::PatchTableFactory with ENDCAP_GREGORY_BASIS (double precision) and
// every builder patch must reappear among the table's patches, evaluated from its local point
// stencils; the largest difference is printed to stderr.
//
// Output (stdout), one block per patch:
//   patch CAGE LEVEL FACE
//   corner NUMFACES PATCHFACE BOUNDARY SHARP DART X Y Z      (4 lines, corners in order)
//   ring N X Y Z X Y Z ...                                  (after each corner line)
//   point X Y Z                                             (20 lines, P Ep Em Fp Fm per corner)
//   eval U V X Y Z DUX DUY DUZ DVX DVY DVZ                  (a few samples of EvalBasisGregory)
#include <opensubdiv/far/catmarkPatchBuilder.h>
#include <opensubdiv/far/patchBasis.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>

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
    std::vector<int> faces;  // quads
    Sdc::Options::VtxBoundaryInterpolation boundary = Sdc::Options::VTX_BOUNDARY_EDGE_ONLY;
    std::vector<int> corners;  // infinitely sharp vertices
    std::vector<int> creases;  // vertex pairs of infinitely sharp edges
};

// Exposes the builder's source-patch assembly, which Far keeps protected.
struct Probe : Far::CatmarkPatchBuilder {
    Probe(Far::TopologyRefiner const &r, Options const &o) : Far::CatmarkPatchBuilder(r, o) {}
    using Far::PatchBuilder::assembleIrregularSourcePatch;
};

// A deterministic jitter so that no configuration is accidentally symmetric.
static double jitter(int i, int k) { return 0.1 * std::sin(12.9898 * i + 78.233 * k + 1.0); }

// n sectors of k x k quads around vertex 0, closed or open (as tessera's test fan_mesh).
static Cage fan(std::string name, int n, int k, bool closed) {
    Cage c;
    c.name = name;
    int spokes = closed ? n : n + 1;
    auto g = [&](int j, int a, int b) {
        if (a == 0 && b == 0) return 0;
        if (b == 0) return 1 + j * k + (a - 1);
        if (a == 0) return 1 + ((j + 1) % spokes) * k + (b - 1);
        return 1 + spokes * k + j * k * k + (a - 1) * k + (b - 1);
    };
    c.pos.resize(1 + spokes * k + n * k * k);
    double step = (closed ? 2.0 : 1.0) * M_PI / n;
    for (int j = 0; j < n; ++j)
        for (int a = 0; a <= k; ++a)
            for (int b = 0; b <= k; ++b) {
                P3 &p = c.pos[g(j, a, b)];
                p.x = a * std::cos(step * j) + b * std::cos(step * (j + 1));
                p.y = a * std::sin(step * j) + b * std::sin(step * (j + 1));
            }
    for (int j = 0; j < n; ++j)
        for (int a = 0; a < k; ++a)
            for (int b = 0; b < k; ++b) {
                int q[4] = {g(j, a, b), g(j, a + 1, b), g(j, a + 1, b + 1), g(j, a, b + 1)};
                c.faces.insert(c.faces.end(), q, q + 4);
            }
    for (size_t i = 0; i < c.pos.size(); ++i) {
        c.pos[i].x += jitter(i, 0);
        c.pos[i].y += jitter(i, 1);
        c.pos[i].z += 0.3 * jitter(i, 2);
    }
    return c;
}

static Cage cube() {
    Cage c;
    c.name = "cube";
    for (int i = 0; i < 8; ++i) {
        P3 p;
        p.x = (i & 1 ? 1 : -1) + jitter(i, 0);
        p.y = (i & 2 ? 1 : -1) + jitter(i, 1);
        p.z = (i & 4 ? 1 : -1) + jitter(i, 2);
        c.pos.push_back(p);
    }
    int f[24] = {0, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 0, 4, 6, 2, 1, 3, 7, 5};
    c.faces.assign(f, f + 24);
    return c;
}

// Two quads sharing two edges at vertex 0 (a valence-2 interior vertex), ringed by a band
// of four quads so that the val-2 vertex's neighbours are interior.
static Cage val2() {
    Cage c;
    c.name = "val2";
    double xy[10][2] = {{0, 0},  {1, 0},   {0, 1},  {-1, 0}, {0, -1},
                        {2, -2}, {2, 2},   {-2, 2}, {-2, -2}, {0, 0}};
    for (int i = 0; i < 9; ++i) {
        P3 p;
        p.x = xy[i][0] + jitter(i, 0);
        p.y = xy[i][1] + jitter(i, 1);
        p.z = 0.3 * jitter(i, 2);
        c.pos.push_back(p);
    }
    // vertex 0 joined to 1 and 3; the two inner quads (0 1 2 3) and (0 3 4 1).
    int f[] = {0, 1, 2, 3, 0, 3, 4, 1, 1, 6, 7, 2, 2, 7, 8, 3, 3, 8, 5, 4, 4, 5, 6, 1};
    c.faces.assign(f, f + sizeof(f) / sizeof(f[0]));
    return c;
}

static double run(Cage const &cage) {
    typedef Far::TopologyDescriptor Desc;
    int nf = (int)cage.faces.size() / 4;
    std::vector<int> counts(nf, 4);
    std::vector<float> cornerWeights(cage.corners.size(), Sdc::Crease::SHARPNESS_INFINITE);
    Desc desc;
    desc.numVertices = (int)cage.pos.size();
    desc.numFaces = nf;
    desc.numVertsPerFace = counts.data();
    desc.vertIndicesPerFace = cage.faces.data();
    desc.numCorners = (int)cage.corners.size();
    desc.cornerVertexIndices = cage.corners.data();
    desc.cornerWeights = cornerWeights.data();
    std::vector<float> creaseWeights(cage.creases.size() / 2, Sdc::Crease::SHARPNESS_INFINITE);
    desc.numCreases = (int)creaseWeights.size();
    desc.creaseVertexIndexPairs = cage.creases.data();
    desc.creaseWeights = creaseWeights.data();
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(cage.boundary);
    Far::TopologyRefiner *refiner = Far::TopologyRefinerFactory<Desc>::Create(
        desc, Far::TopologyRefinerFactory<Desc>::Options(Sdc::SCHEME_CATMARK, sdc));

    Far::TopologyRefiner::AdaptiveOptions adaptive(2);
    adaptive.useInfSharpPatch = true;
    adaptive.useSingleCreasePatch = false;
    refiner->RefineAdaptive(adaptive);

    // Positions of every level, concatenated (the order local point stencils refer to).
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

            std::printf("patch %s %d %d\n", cage.name.c_str(), l, f);
            for (int c = 0; c < 4; ++c) {
                Far::SourcePatch::Corner const &sc = sp._corners[c];
                P3 const &v = lp[src[c]];
                std::printf("corner %d %d %d %d %d %.17g %.17g %.17g\n", sc._numFaces, sc._patchFace,
                            sc._boundary, sc._sharp, sc._dart, v.x, v.y, v.z);
                std::vector<int> ring(sp.GetCornerRingSize(c));
                sp.GetCornerRingPoints(c, ring.data());
                std::printf("ring %d", (int)ring.size());
                for (int r : ring) std::printf(" %.17g %.17g %.17g", lp[src[r]].x, lp[src[r]].y, lp[src[r]].z);
                std::printf("\n");
            }
            std::vector<P3> pts(m.GetNumRows());
            for (int row = 0; row < m.GetNumRows(); ++row) {
                auto cols = m.GetRowColumns(row);
                auto w = m.GetRowElements(row);
                for (int e = 0; e < m.GetRowSize(row); ++e) pts[row].AddWithWeight(lp[src[cols[e]]], w[e]);
                std::printf("point %.17g %.17g %.17g\n", pts[row].x, pts[row].y, pts[row].z);
            }
            // Far::internal::EvalBasisGregory with the build's default (approximate) derivatives.
            double const uv[5][2] = {{0.25, 0.5}, {0.9, 0.1}, {0.5, 0.5}, {0.0, 0.3}, {0.7, 1.0}};
            for (auto const &st : uv) {
                double w[20], wu[20], wv[20];
                Far::internal::EvalBasisGregory<double>(st[0], st[1], w, wu, wv, 0, 0, 0);
                P3 e, eu, ev;
                for (int k = 0; k < 20; ++k) {
                    e.AddWithWeight(pts[k], w[k]);
                    eu.AddWithWeight(pts[k], wu[k]);
                    ev.AddWithWeight(pts[k], wv[k]);
                }
                std::printf("eval %g %g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", st[0], st[1],
                            e.x, e.y, e.z, eu.x, eu.y, eu.z, ev.x, ev.y, ev.z);
            }
            builderPatches.push_back(pts);
        }
    }

    // The same patches through the patch table's local point stencils.
    Far::PatchTableFactory::Options tableOptions(2);
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
        if (table->GetPatchArrayDescriptor(a).GetType() != Far::PatchDescriptor::GREGORY_BASIS) continue;
        for (int p = 0; p < table->GetNumPatches(a); ++p) {
            auto cvs = table->GetPatchVertices(a, p);
            std::vector<P3> pts;
            for (int k = 0; k < cvs.size(); ++k)
                pts.push_back(cvs[k] < (int)all.size() ? all[cvs[k]] : local[cvs[k] - all.size()]);
            tablePatches.push_back(pts);
        }
    }
    auto diff = [](std::vector<P3> const &a, std::vector<P3> const &b) {
        double d = 0;
        for (size_t i = 0; i < a.size(); ++i)
            d = std::max(d, std::max(std::fabs(a[i].x - b[i].x),
                                     std::max(std::fabs(a[i].y - b[i].y), std::fabs(a[i].z - b[i].z))));
        return d;
    };
    double worst = 0;
    for (auto const &bp : builderPatches) {
        double best = 1e300;
        for (auto const &tp : tablePatches) best = std::min(best, diff(bp, tp));
        worst = std::max(worst, best);
    }
    std::fprintf(stderr, "%s: %zu builder patches, %zu table Gregory patches, max builder-table difference %.3g\n",
                 cage.name.c_str(), builderPatches.size(), tablePatches.size(), worst);
    delete table;
    delete refiner;
    return worst;
}

int main() {
    std::vector<Cage> cages;
    cages.push_back(cube());
    cages.push_back(fan("fan5", 5, 2, true));  // valence 5 inside, one-face corners on the rim
    cages.push_back(fan("fan3", 3, 2, true));
    Cage open3 = fan("open3_corners", 3, 2, false);  // irregular boundary vertex, sharp rim corners
    open3.boundary = Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER;
    cages.push_back(open3);
    Cage open1 = fan("open1_sharp", 1, 3, false);  // a one-face corner tagged sharp, valence 3 and 5 inside
    open1.corners.push_back(0);
    cages.push_back(open1);
    Cage open4 = fan("open4_dart", 4, 2, false);  // boundary vertex of 4 faces with an inf-sharp corner tag
    open4.corners.push_back(0);
    cages.push_back(open4);
    cages.push_back(val2());
    Cage corner5 = fan("fan5_corner", 5, 2, true);  // an interior vertex tagged sharp
    corner5.corners.push_back(0);
    cages.push_back(corner5);
    Cage dart5 = fan("fan5_dart", 5, 3, true);  // a dart: one inf-sharp edge from the centre
    dart5.creases = {0, 1, 1, 2};                 // along the first spoke, two edges long
    cages.push_back(dart5);
    double worst = 0;
    for (auto const &c : cages) worst = std::max(worst, run(c));
    return worst < 1e-12 ? 0 : 1;
}
