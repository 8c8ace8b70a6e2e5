// osd_oracle: print OpenSubdiv Bfr limit-surface tessellations of an OBJ cage.
//
// This is a test oracle for tessera's own Catmull-Clark evaluator. It is not
// part of tessera and tessera does not link to OpenSubdiv. See README.md in
// this folder for the output format, the options and the measured results.
//
// Usage:
//   osd_oracle [--normals] [--facets] [--scheme catmark|loop|bilinear]
//              [--float] [--no-cache] [--approx-smooth L] [--approx-sharp L]
//              CAGE.obj [RATE]
//
// Pipeline: own OBJ + tag parser -> Far::TopologyDescriptor ->
// Far::TopologyRefiner (Sdc options from the tags, defaults as OpenSubdiv's
// regression tools) -> Bfr::RefinerSurfaceFactory (default Options) ->
// per face Bfr::Surface<double> + Bfr::Tessellation(uniform RATE, default
// Options) -> Surface::Evaluate at every tessellation coord.

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/bfr/tessellation.h>
#include <opensubdiv/far/error.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/version.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace OpenSubdiv;

namespace {

// ---------------------------------------------------------------------------
// Diagnostics

std::string g_path;
int g_warnings = 0;

[[noreturn]] void die(const std::string &msg) {
    std::fprintf(stderr, "osd_oracle: %s: %s\n", g_path.c_str(), msg.c_str());
    std::exit(2);
}

void warn(const std::string &msg) {
    ++g_warnings;
    std::fprintf(stderr, "osd_oracle: %s: warning: %s\n", g_path.c_str(), msg.c_str());
}

void farError(Far::ErrorType, const char *msg) {
    std::fprintf(stderr, "osd_oracle: %s: OpenSubdiv error: %s\n", g_path.c_str(), msg);
}

void farWarning(const char *msg) {
    ++g_warnings;
    std::fprintf(stderr, "osd_oracle: %s: OpenSubdiv warning: %s\n", g_path.c_str(), msg);
}

// ---------------------------------------------------------------------------
// Cage: the OBJ + tag reader (shared with bfr_bench.cpp)

#include "cage_reader.h"

// ---------------------------------------------------------------------------

void usage() {
    std::fprintf(stderr,
                 "usage: osd_oracle [--normals] [--facets] [--scheme catmark|loop|bilinear]\n"
                 "                  [--float] [--no-cache] [--approx-smooth L] [--approx-sharp L]\n"
                 "                  CAGE.obj [RATE]\n"
                 "  RATE      uniform Bfr::Tessellation rate (default 1)\n"
                 "  --scheme  default: loop if the file name starts with 'loop_', else catmark\n"
                 "  --normals also print nx ny nz = normalize(dP/du x dP/dv) per point\n"
                 "  --facets  also print the tessellation's triangles after each face's points\n"
                 "  --float   evaluate with Bfr::Surface<float> (default: double)\n"
                 "  --no-cache  disable the SurfaceFactory's topology cache (cross-check)\n"
                 "  --approx-smooth L, --approx-sharp L  override SurfaceFactory::Options'\n"
                 "            approximation levels (defaults 2 and 6; diagnostics only)\n");
    std::exit(64);
}

template <typename REAL>
int run(const Cage &cage, const Topology &topo, int rate, bool normals, bool facets,
        bool noCache, int smoothLevel, int sharpLevel) {
    Far::TopologyRefiner *refiner = createRefiner(cage, topo);

    // The descriptor factory silently skips creases whose edge does not exist;
    // say so.
    const Far::TopologyLevel &base = refiner->GetLevel(0);
    for (size_t k = 0; k < topo.creaseWeights.size(); ++k) {
        int a = topo.creasePairs[2 * k], b = topo.creasePairs[2 * k + 1];
        if (base.FindEdge(a, b) == Far::INDEX_INVALID)
            warn("crease (" + std::to_string(a) + "," + std::to_string(b) +
                 ") is not an edge of the cage, ignored");
    }

    // Default SurfaceFactory::Options (approximation levels 2 smooth / 6
    // sharp, caching on, no default face-varying ID); --no-cache only turns
    // the topology cache off, as a cross-check.
    Bfr::SurfaceFactory::Options factoryOptions;
    if (noCache) factoryOptions.EnableCaching(false);
    if (smoothLevel >= 0) factoryOptions.SetApproxLevelSmooth(smoothLevel);
    if (sharpLevel >= 0) factoryOptions.SetApproxLevelSharp(sharpLevel);
    Bfr::RefinerSurfaceFactory<> factory(*refiner, factoryOptions);

    std::vector<REAL> meshPos(cage.pos.begin(), cage.pos.end());
    typedef typename Bfr::Surface<REAL>::PointDescriptor PointDesc;
    PointDesc pointDesc(3);

    const int nf = cage.numFaces();
    std::printf("# osd_oracle opensubdiv %d.%d.%d scheme %s boundary %s crease %s triangles %s "
                "real %s approx-smooth %d approx-sharp %d cache %s rate %d faces %d vertices %d\n",
                OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR, OPENSUBDIV_VERSION_PATCH,
                schemeName(topo.scheme),
                boundaryName(topo.options.GetVtxBoundaryInterpolation()),
                topo.options.GetCreasingMethod() == Sdc::Options::CREASE_CHAIKIN ? "chaikin" : "uniform",
                topo.options.GetTriangleSubdivision() == Sdc::Options::TRI_SUB_SMOOTH ? "smooth" : "catmark",
                sizeof(REAL) == 8 ? "double" : "float", factoryOptions.GetApproxLevelSmooth(),
                factoryOptions.GetApproxLevelSharp(), factoryOptions.IsCachingEnabled() ? "on" : "off",
                rate, nf, cage.numVertices());

    std::vector<char> taggedHole(nf, 0);
    for (int h : topo.holes) taggedHole[h] = 1;

    Bfr::Surface<REAL> surface;
    std::vector<REAL> patchPoints, coords;
    std::vector<int> tris;
    long totalPoints = 0;
    int noLimit = 0, failed = 0, numRegular = 0;
    for (int f = 0; f < nf; ++f) {
        const int K = cage.faceSizes[f];
        if (!factory.FaceHasLimitSurface(f)) {
            // "hole": a 't hole' tag; "boundary": excluded by boundary
            // interpolation "none" (Far tags such faces as holes itself:
            // far/topologyRefinerFactory.cpp, makeBoundaryFacesHoles).
            std::printf("face %d vertices %d points 0 nolimit %s\n", f, K,
                        taggedHole[f] ? "hole" : "boundary");
            ++noLimit;
            continue;
        }
        if (!factory.InitVertexSurface<REAL>(f, &surface)) {
            std::printf("face %d vertices %d points 0 nolimit failed\n", f, K);
            warn("InitVertexSurface failed for face " + std::to_string(f));
            ++failed;
            continue;
        }
        Bfr::Parameterization param = surface.GetParameterization();
        Bfr::Tessellation tess(param, rate);  // default Tessellation::Options
        if (!tess.IsValid()) die("invalid Bfr::Tessellation for face " + std::to_string(f));

        const int M = tess.GetNumCoords();
        coords.resize(2 * (size_t)M);
        tess.GetCoords(coords.data());

        patchPoints.resize(3 * (size_t)surface.GetNumPatchPoints());
        surface.PreparePatchPoints(meshPos.data(), pointDesc, patchPoints.data(), pointDesc);

        // Bfr's own classification: a single regular B-spline (or Loop box-
        // spline) patch, a linear patch, or an irregular patch (PatchTree).
        const char *kind = surface.IsRegular() ? "regular" : surface.IsLinear() ? "linear" : "irregular";
        if (surface.IsRegular()) ++numRegular;
        std::printf("face %d vertices %d points %d %s\n", f, K, M, kind);
        for (int i = 0; i < M; ++i) {
            REAL P[3], Du[3], Dv[3];
            surface.Evaluate(&coords[2 * i], patchPoints.data(), pointDesc, P, Du, Dv);
            std::printf("%.17g %.17g %.17g %.17g %.17g", (double)coords[2 * i],
                        (double)coords[2 * i + 1], (double)P[0], (double)P[1], (double)P[2]);
            if (normals) {
                double n[3] = {(double)Du[1] * Dv[2] - (double)Du[2] * Dv[1],
                               (double)Du[2] * Dv[0] - (double)Du[0] * Dv[2],
                               (double)Du[0] * Dv[1] - (double)Du[1] * Dv[0]};
                double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                if (len > 0.0) { n[0] /= len; n[1] /= len; n[2] /= len; }
                std::printf(" %.17g %.17g %.17g", n[0], n[1], n[2]);
            }
            std::printf("\n");
        }
        if (facets) {
            const int T = tess.GetNumFacets();
            tris.resize(3 * (size_t)T);
            tess.GetFacets(tris.data());
            std::printf("facets %d\n", T);
            for (int t = 0; t < T; ++t)
                std::printf("%d %d %d\n", tris[3 * t], tris[3 * t + 1], tris[3 * t + 2]);
        }
        totalPoints += M;
    }
    std::printf("# end faces %d points %ld nolimit %d failed %d warnings %d regular %d\n", nf,
                totalPoints, noLimit, failed, g_warnings, numRegular);
    delete refiner;
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) die("write error on stdout");
    return failed ? 3 : 0;
}

}  // namespace

int main(int argc, char **argv) {
    bool normals = false, facets = false, useFloat = false, noCache = false;
    int smoothLevel = -1, sharpLevel = -1;
    auto level = [&](const char *v) {
        long l;
        if (!parseInt(v, l) || l < 0 || l > 10) {
            std::fprintf(stderr, "osd_oracle: approximation levels must be in 0..10\n");
            std::exit(64);
        }
        return (int)l;
    };
    std::string schemeArg, path;
    int rate = 1;
    bool haveRate = false;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--normals") normals = true;
        else if (a == "--facets") facets = true;
        else if (a == "--float") useFloat = true;
        else if (a == "--no-cache") noCache = true;
        else if (a == "--approx-smooth" && i + 1 < argc) smoothLevel = level(argv[++i]);
        else if (a == "--approx-sharp" && i + 1 < argc) sharpLevel = level(argv[++i]);
        else if (a == "--scheme" && i + 1 < argc) schemeArg = argv[++i];
        else if (a == "-h" || a == "--help") usage();
        else if (!a.empty() && a[0] == '-') usage();
        else if (path.empty()) path = a;
        else if (!haveRate) {
            long r;
            if (!parseInt(a, r) || r < 1 || r > 1000) {
                std::fprintf(stderr, "osd_oracle: RATE must be an integer in 1..1000\n");
                return 64;
            }
            rate = (int)r;
            haveRate = true;
        } else usage();
    }
    if (path.empty()) usage();
    g_path = path;

    Sdc::SchemeType scheme = Sdc::SCHEME_CATMARK;
    std::string base = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
    if (schemeArg.empty()) scheme = base.rfind("loop_", 0) == 0 ? Sdc::SCHEME_LOOP : Sdc::SCHEME_CATMARK;
    else if (schemeArg == "catmark") scheme = Sdc::SCHEME_CATMARK;
    else if (schemeArg == "loop") scheme = Sdc::SCHEME_LOOP;
    else if (schemeArg == "bilinear") scheme = Sdc::SCHEME_BILINEAR;
    else usage();

#if OPENSUBDIV_VERSION_NUMBER < 30501
    // Not counted as a warning: informational, printed for every cage.
    std::fprintf(stderr, "osd_oracle: note: built against OpenSubdiv %d.%d.%d, whose Bfr mishandles "
                         "valence-2 interior vertices (fixed in 3.5.1, commit 51eb6a04); use a 3.6.0 "
                         "build for reference data (README.md)\n",
                 OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR, OPENSUBDIV_VERSION_PATCH);
#endif
    Far::SetErrorCallback(farError);
    Far::SetWarningCallback(farWarning);

    Cage cage = readCage(path);
    if (scheme == Sdc::SCHEME_LOOP) {
        for (int f = 0; f < cage.numFaces(); ++f)
            if (cage.faceSizes[f] != 3)
                die("face " + std::to_string(f) + " has " + std::to_string(cage.faceSizes[f]) +
                    " vertices; the Loop scheme needs triangles");
    }
    Topology topo = applyTags(cage, scheme);
    return useFloat ? run<float>(cage, topo, rate, normals, facets, noCache, smoothLevel, sharpLevel)
                    : run<double>(cage, topo, rate, normals, facets, noCache, smoothLevel,
                                          sharpLevel);
}
