// Triangle patch basis oracle: prints OpenSubdiv's own basis weights of the two patch types
// it evaluates Loop surfaces with -- LOOP (the 12-point quartic box-spline triangle, under
// every value of the 5-bit triangle boundary mask) and GREGORY_TRIANGLE (18 points) -- for
// tessera's surface::quartic_triangle and surface::gregory_triangle tests.
//
// The weights come from Far::internal::EvaluatePatchBasisNormalized<double> (far/patchBasis.cpp),
// the entry point Far's patch tables and Bfr call once a patch's parameters are normalised to
// its own triangle, with a PatchParam that carries only the boundary mask (depth 0, not
// rotated), so no parameter scaling or rotation enters. The library is built without
// OPENSUBDIV_GREGORY_EVAL_TRUE_DERIVATIVES, as by default.
//
// The (u, v) table: the three corners, points on each edge (dyadic, so that u + v = 1 holds
// exactly on the hypotenuse), points a hair away from each corner (where the Gregory blend
// tends to 0/0), and interior points from a seeded generator. Every point is evaluated as
// LOOP with mask 0 and as GREGORY_TRIANGLE; a subset (corners, one point per edge, a few
// interior points) as LOOP under each non-zero mask 1..31.
//
// Output (stdout), after one '#' line:
//   loop MASK U V            then three lines p / du / dv, 12 weights each
//   gregory U V              then three lines p / du / dv, 18 weights each
#include <opensubdiv/far/patchBasis.h>
#include <opensubdiv/far/patchDescriptor.h>
#include <opensubdiv/far/patchParam.h>
#include <opensubdiv/version.h>

#include <cstdint>
#include <cstdio>
#include <utility>
#include <vector>

using namespace OpenSubdiv;

#define STRINGIZE_(x) #x
#define STRINGIZE(x) STRINGIZE_(x)

static void printWeights(const char *tag, const double *w, int n) {
    std::printf("%s", tag);
    for (int i = 0; i < n; ++i) std::printf(" %.17g", w[i]);
    std::printf("\n");
}

static void evaluate(Far::PatchDescriptor::Type type, int mask, double u, double v) {
    Far::PatchParam param;
    param.Set(/*faceid*/ 0, /*u*/ 0, /*v*/ 0, /*depth*/ 0, /*nonquad*/ false,
              (unsigned short)mask, /*transition*/ 0, /*regular*/ true);
    double wP[20], wDu[20], wDv[20];
    int n = Far::internal::EvaluatePatchBasisNormalized<double>(type, param, u, v, wP, wDu, wDv,
                                                                nullptr, nullptr, nullptr);
    if (type == Far::PatchDescriptor::LOOP)
        std::printf("loop %d %.17g %.17g\n", mask, u, v);
    else
        std::printf("gregory %.17g %.17g\n", u, v);
    printWeights("p", wP, n);
    printWeights("du", wDu, n);
    printWeights("dv", wDv, n);
}

int main() {
    std::vector<std::pair<double, double>> all, subset;
    // Corners c0, c1, c2.
    for (auto c : {std::make_pair(0.0, 0.0), std::make_pair(1.0, 0.0), std::make_pair(0.0, 1.0)}) {
        all.push_back(c);
        subset.push_back(c);
    }
    // Edges: e0 (v = 0), e1 (u + v = 1), e2 (u = 0).
    for (double t : {0.125, 0.5, 0.8125}) {
        all.push_back({t, 0.0});
        all.push_back({1.0 - t, t});
        all.push_back({0.0, 1.0 - t});
    }
    subset.push_back({0.375, 0.0});
    subset.push_back({0.625, 0.375});
    subset.push_back({0.0, 0.6875});
    // A hair away from each corner, along and across its edges.
    const double h = 1e-9;
    for (auto p : {std::make_pair(h, 0.0), std::make_pair(0.0, h), std::make_pair(h, h),
                   std::make_pair(1.0 - h, 0.0), std::make_pair(1.0 - h, h), std::make_pair(1.0 - 2 * h, h),
                   std::make_pair(0.0, 1.0 - h), std::make_pair(h, 1.0 - h), std::make_pair(h, 1.0 - 2 * h)})
        all.push_back(p);
    // Seeded interior points (Knuth's MMIX LCG, top 53 bits), rejected outside u + v < 1.
    std::uint64_t state = 20260604;
    auto unit = [&state]() {
        state = state * 6364136223846793005ULL + 1442695040888963407ULL;
        return (double)(state >> 11) / 9007199254740992.0;
    };
    int interior = 0;
    while (interior < 16) {
        double u = unit(), v = unit();
        if (u + v >= 1.0) continue;
        all.push_back({u, v});
        if (interior < 4) subset.push_back({u, v});
        ++interior;
    }

    std::printf("# OpenSubdiv %s basis weights (p, d/du, d/dv) of LOOP (mask 0 at every point, masks 1..31 "
                "at a subset) and GREGORY_TRIANGLE, from Far::internal::EvaluatePatchBasisNormalized<double>; "
                "written by tools/osd-oracle/tri_basis_check.sh\n",
                STRINGIZE(OPENSUBDIV_VERSION));
    for (auto [u, v] : all) {
        evaluate(Far::PatchDescriptor::LOOP, 0, u, v);
        evaluate(Far::PatchDescriptor::GREGORY_TRIANGLE, 0, u, v);
    }
    for (int mask = 1; mask < 32; ++mask)
        for (auto [u, v] : subset) evaluate(Far::PatchDescriptor::LOOP, mask, u, v);
    return 0;
}
