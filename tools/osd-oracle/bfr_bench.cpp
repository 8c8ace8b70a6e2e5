// bfr_bench: time OpenSubdiv Bfr tessellating a replicated OBJ cage, as a consumer would.
//
// A benchmark for comparing tessera's throughput against OpenSubdiv's Bfr. It is not
// part of tessera and tessera does not link to OpenSubdiv. Build: bfr_bench.sh.
//
// Usage:
//   bfr_bench [--threads T] [--rate N] [--copies K] [--repeat R] [--float]
//             [--adaptive-rates FILE] CAGE.obj
//
// Pipeline: OBJ + tag parser (tools/osd-oracle/cage_reader.h, shared with osd_oracle.cpp) -> the cage replicated K
// times along x (default: enough copies for >= 50,000 faces) -> Far::TopologyRefiner
// (Sdc options from the tags, defaults as OpenSubdiv's regression tools) ->
// Bfr::RefinerSurfaceFactory (default Options) [timed: "setup"] -> R timed passes, each
// tessellating every face on T std::threads (contiguous blocks of faces): per face
// InitVertexSurface, PreparePatchPoints, Bfr::Tessellation (uniform rate N, or the
// face's rates from FILE; default Tessellation::Options), GetCoords, Evaluate P, dP/du,
// dP/dv at every coord, normal = normalize(dP/du x dP/dv), GetFacets (indices offset to
// the thread's point array) -> per-thread arrays of float x y z nx ny nz and int
// triangles, grown during the first pass only.
//
// Output (stdout): a '#' header line, one 'repeat' line per pass and finally
//   bfr_bench faces F triangles T points P threads N rate R setup_ms S median_ms M mtri_per_s X
// (R is 'adaptive' with --adaptive-rates). Errors: one 'bfr_bench: ...' line on stderr,
// exit status 2. Exit status 3 if any face failed InitVertexSurface.

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/bfr/surfaceFactoryCache.h>
#include <opensubdiv/bfr/tessellation.h>
#include <opensubdiv/far/error.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/version.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <shared_mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace OpenSubdiv;

namespace {

// ---------------------------------------------------------------------------
// Diagnostics

std::string g_path;
int g_warnings = 0;

[[noreturn]] void fail(const std::string &msg) {
    std::fprintf(stderr, "bfr_bench: %s\n", msg.c_str());
    std::exit(2);
}

[[noreturn]] void die(const std::string &msg) { fail(g_path + ": " + msg); }

void warn(const std::string &msg) {
    ++g_warnings;
    std::fprintf(stderr, "bfr_bench: %s: warning: %s\n", g_path.c_str(), msg.c_str());
}

void farError(Far::ErrorType, const char *msg) {
    std::fprintf(stderr, "bfr_bench: %s: OpenSubdiv error: %s\n", g_path.c_str(), msg);
}

void farWarning(const char *msg) {
    ++g_warnings;
    std::fprintf(stderr, "bfr_bench: %s: OpenSubdiv warning: %s\n", g_path.c_str(), msg);
}

// ---------------------------------------------------------------------------
// Cage: the OBJ + tag reader (shared with osd_oracle.cpp)

#include "cage_reader.h"

// ---------------------------------------------------------------------------
// Replication

// K copies of the cage, copy c's vertices offset along x by c * 1.5 * (bbox width), so
// the copies are disjoint. Vertex tags (crease, corner) and face tags (hole) are
// replicated with their indices offset; the other tags are global and kept once.
Cage replicate(const Cage &cage, int K) {
    if (K == 1) return cage;
    const long nv = cage.numVertices(), nf = cage.numFaces();
    double xmin = cage.pos[0], xmax = cage.pos[0];
    for (long v = 0; v < nv; ++v) {
        xmin = std::min(xmin, cage.pos[3 * v]);
        xmax = std::max(xmax, cage.pos[3 * v]);
    }
    double width = xmax - xmin;
    if (!(width > 0.0)) width = 1.0;  // a cage flat in x: any positive spacing is disjoint
    Cage out;
    out.pos.reserve(cage.pos.size() * K);
    out.faceSizes.reserve(cage.faceSizes.size() * K);
    out.faceVerts.reserve(cage.faceVerts.size() * K);
    for (int c = 0; c < K; ++c) {
        const double dx = c * 1.5 * width;
        for (long v = 0; v < nv; ++v) {
            out.pos.push_back(cage.pos[3 * v] + dx);
            out.pos.push_back(cage.pos[3 * v + 1]);
            out.pos.push_back(cage.pos[3 * v + 2]);
        }
        out.faceSizes.insert(out.faceSizes.end(), cage.faceSizes.begin(), cage.faceSizes.end());
        for (int i : cage.faceVerts) out.faceVerts.push_back((int)(i + c * nv));
    }
    for (const Tag &t : cage.tags) {
        long stride;
        if (t.name == "crease" || t.name == "corner") stride = nv;
        else if (t.name == "hole") stride = nf;
        else {
            out.tags.push_back(t);
            continue;
        }
        for (int c = 0; c < K; ++c) {
            Tag r = t;
            // Out-of-range indices stay out of range (applyTags rejects them).
            for (int &i : r.ints)
                if (i >= 0 && i < stride) i = (int)(i + c * stride);
            out.tags.push_back(r);
        }
    }
    return out;
}

// ---------------------------------------------------------------------------
// Adaptive rates: one line per face, the face's rates separated by white space. As
// Bfr::Tessellation accepts: 1 (uniform), N (edges), N+1 (edges + inner) rates, or for a
// quad also 2 (inner) or N+2 (edges + 2 inner). Rates are integers in 1..kMaxRate.

const int kMaxRate = 1000;

struct Rates {
    std::vector<int> offset;  // per face, into values; offset[nf] = values.size()
    std::vector<int> values;
};

Rates readRates(const std::string &path, const Cage &cage) {
    std::ifstream in(path);
    if (!in) fail(path + ": cannot open adaptive-rates file");
    Rates r;
    const int nf = cage.numFaces();
    std::string line;
    long lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (lineNo > nf) {
            if (line.find_first_not_of(" \t") == std::string::npos) continue;  // trailing blank
            fail(path + ": more than " + std::to_string(nf) +
                 " lines, expected one per face of the replicated cage (" + std::to_string(nf) +
                 " faces)");
        }
        const int f = (int)(lineNo - 1), N = cage.faceSizes[f];
        r.offset.push_back((int)r.values.size());
        std::istringstream ls(line);
        std::string tok;
        int n = 0;
        while (ls >> tok) {
            long v;
            if (!parseInt(tok, v) || v < 1 || v > kMaxRate)
                fail(path + ": line " + std::to_string(lineNo) + ": bad rate '" + tok +
                     "' (an integer in 1.." + std::to_string(kMaxRate) + ")");
            r.values.push_back((int)v);
            ++n;
        }
        bool ok = n == 1 || n == N || n == N + 1 || (N == 4 && (n == 2 || n == N + 2));
        if (!ok)
            fail(path + ": line " + std::to_string(lineNo) + ": face " + std::to_string(f) +
                 " has " + std::to_string(N) + " edges but the line has " + std::to_string(n) +
                 " rates (expected " + std::to_string(N) + ", or 1, " + std::to_string(N + 1) +
                 (N == 4 ? ", 2, 6" : "") + ")");
    }
    if (in.bad()) fail(path + ": read error");
    if (lineNo < nf)
        fail(path + ": " + std::to_string(lineNo) + " lines, expected one per face of the " +
             "replicated cage (" + std::to_string(nf) + " faces)");
    r.offset.push_back((int)r.values.size());
    return r;
}

// ---------------------------------------------------------------------------
// Benchmark

typedef std::chrono::steady_clock Clock;

double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// One thread's output and scratch space, kept across passes so that only the first pass
// grows them. Aligned so that neighbouring threads' counters share no cache line.
template <typename REAL>
struct alignas(64) Worker {
    std::vector<float> points;  // 6 per point: x y z nx ny nz
    std::vector<int> tris;      // 3 per triangle, indices into this thread's points
    std::vector<REAL> patchPoints, coords;
    Bfr::Surface<REAL> surface;
    long numPoints = 0, numTris = 0;
    int failed = 0, noLimit = 0;
};

// The threads share one factory, so its topology cache must be the thread-safe one: the
// default `SurfaceFactoryCache` is not, and two threads inserting irregular faces' topology
// into it at once crashed about one run in ten (Loop cube, 2 threads, adaptive rates).
typedef Bfr::SurfaceFactoryCacheThreaded<std::shared_mutex, std::shared_lock<std::shared_mutex>,
                                         std::unique_lock<std::shared_mutex>>
    ThreadSafeCache;
typedef Bfr::RefinerSurfaceFactory<ThreadSafeCache> SurfaceFactory;

template <typename REAL>
void tessellateFaces(const SurfaceFactory &factory, const std::vector<REAL> &meshPos,
                     int rate, const Rates *rates, int begin, int end, Worker<REAL> &w) {
    typedef typename Bfr::Surface<REAL>::PointDescriptor PointDesc;
    const PointDesc pointDesc(3);
    const Bfr::Tessellation::Options tessOptions;  // defaults: triangles, coord stride 2
    Bfr::Surface<REAL> &surface = w.surface;
    long nPts = 0, nTris = 0;
    int failed = 0, noLimit = 0;
    for (int f = begin; f < end; ++f) {
        if (!factory.FaceHasLimitSurface(f)) {
            ++noLimit;
            continue;
        }
        if (!factory.InitVertexSurface<REAL>(f, &surface)) {
            ++failed;
            continue;
        }
        w.patchPoints.resize(3 * (size_t)surface.GetNumPatchPoints());
        surface.PreparePatchPoints(meshPos.data(), pointDesc, w.patchPoints.data(), pointDesc);

        const Bfr::Parameterization param = surface.GetParameterization();
        Bfr::Tessellation tess =
            rates ? Bfr::Tessellation(param, rates->offset[f + 1] - rates->offset[f],
                                      &rates->values[rates->offset[f]], tessOptions)
                  : Bfr::Tessellation(param, rate, tessOptions);
        const int M = tess.GetNumCoords(), T = tess.GetNumFacets();

        w.coords.resize(2 * (size_t)M);
        tess.GetCoords(w.coords.data());

        const size_t p0 = 6 * (size_t)nPts, t0 = 3 * (size_t)nTris;
        if (w.points.size() < p0 + 6 * (size_t)M) w.points.resize(p0 + 6 * (size_t)M);
        if (w.tris.size() < t0 + 3 * (size_t)T) w.tris.resize(t0 + 3 * (size_t)T);

        float *out = w.points.data() + p0;
        const REAL *uv = w.coords.data();
        const REAL *pp = w.patchPoints.data();
        for (int i = 0; i < M; ++i, out += 6) {
            REAL P[3], Du[3], Dv[3];
            surface.Evaluate(uv + 2 * i, pp, pointDesc, P, Du, Dv);
            REAL n0 = Du[1] * Dv[2] - Du[2] * Dv[1];
            REAL n1 = Du[2] * Dv[0] - Du[0] * Dv[2];
            REAL n2 = Du[0] * Dv[1] - Du[1] * Dv[0];
            REAL len = std::sqrt(n0 * n0 + n1 * n1 + n2 * n2);
            if (len > REAL(0)) {
                REAL inv = REAL(1) / len;
                n0 *= inv;
                n1 *= inv;
                n2 *= inv;
            }
            out[0] = (float)P[0];
            out[1] = (float)P[1];
            out[2] = (float)P[2];
            out[3] = (float)n0;
            out[4] = (float)n1;
            out[5] = (float)n2;
        }
        int *tri = w.tris.data() + t0;
        tess.GetFacets(tri);
        tess.TransformFacetCoordIndices(tri, (int)nPts);  // to this thread's point indices
        nPts += M;
        nTris += T;
    }
    w.numPoints = nPts;
    w.numTris = nTris;
    w.failed = failed;
    w.noLimit = noLimit;
}

struct Args {
    int threads = 2, rate = 16, copies = 0, repeat = 5;
    bool useFloat = false;
    std::string ratesPath, path, scheme;
};

template <typename REAL>
int run(const Cage &cage, const Topology &topo, const Args &args) {
    // ---- setup: refiner + surface factory
    auto s0 = Clock::now();
    Far::TopologyRefiner *refiner = createRefiner(cage, topo);
    SurfaceFactory factory(*refiner);  // default SurfaceFactory::Options, thread-safe cache
    std::vector<REAL> meshPos(cage.pos.begin(), cage.pos.end());
    const double setupMs = msSince(s0);

    Rates rates;
    if (!args.ratesPath.empty()) rates = readRates(args.ratesPath, cage);
    const Rates *ratesPtr = args.ratesPath.empty() ? nullptr : &rates;
    const std::string rateStr = ratesPtr ? "adaptive" : std::to_string(args.rate);

    const int nf = cage.numFaces();
    const int T = std::max(1, std::min(args.threads, nf));
    std::printf("# bfr_bench opensubdiv %d.%d.%d scheme %s boundary %s real %s cage %s copies %d "
                "faces %d vertices %d threads %d rate %s\n",
                OPENSUBDIV_VERSION_MAJOR, OPENSUBDIV_VERSION_MINOR, OPENSUBDIV_VERSION_PATCH,
                schemeName(topo.scheme), boundaryName(topo.options.GetVtxBoundaryInterpolation()),
                sizeof(REAL) == 8 ? "double" : "float", args.path.c_str(), args.copies, nf,
                cage.numVertices(), T, rateStr.c_str());
    std::fflush(stdout);

    std::vector<Worker<REAL>> workers(T);
    std::vector<double> times;
    long numPoints = 0, numTris = 0;
    int failed = 0, noLimit = 0;
    for (int r = 0; r < args.repeat; ++r) {
        auto t0 = Clock::now();
        std::vector<std::thread> pool;
        pool.reserve(T);
        for (int k = 0; k < T; ++k) {
            const int begin = (int)((long)nf * k / T), end = (int)((long)nf * (k + 1) / T);
            pool.emplace_back(tessellateFaces<REAL>, std::cref(factory), std::cref(meshPos),
                              args.rate, ratesPtr, begin, end, std::ref(workers[k]));
        }
        for (std::thread &t : pool) t.join();
        const double ms = msSince(t0);
        times.push_back(ms);
        numPoints = numTris = 0;
        failed = noLimit = 0;
        for (const Worker<REAL> &w : workers) {
            numPoints += w.numPoints;
            numTris += w.numTris;
            failed += w.failed;
            noLimit += w.noLimit;
        }
        std::printf("repeat %d ms %.3f triangles %ld points %ld nolimit %d failed %d mtri_per_s %.3f\n",
                    r, ms, numTris, numPoints, noLimit, failed, numTris / (ms * 1e-3) / 1e6);
        std::fflush(stdout);
    }
    std::vector<double> sorted = times;
    std::sort(sorted.begin(), sorted.end());
    const size_t n = sorted.size();
    const double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    std::printf("bfr_bench faces %d triangles %ld points %ld threads %d rate %s setup_ms %.3f "
                "median_ms %.3f mtri_per_s %.3f\n",
                nf, numTris, numPoints, T, rateStr.c_str(), setupMs, median,
                numTris / (median * 1e-3) / 1e6);
    if (failed) std::fprintf(stderr, "bfr_bench: %s: InitVertexSurface failed for %d faces\n",
                             g_path.c_str(), failed);
    delete refiner;
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) fail("write error on stdout");
    return failed ? 3 : 0;
}

[[noreturn]] void badArgs(const std::string &why) {
    std::fprintf(stderr, "bfr_bench: %s (see --help)\n", why.c_str());
    std::exit(2);
}

[[noreturn]] void help() {
    std::printf("usage: bfr_bench [--threads T] [--rate N] [--copies K] [--repeat R] [--float]\n"
                "                 [--adaptive-rates FILE] CAGE.obj\n"
                "  --threads T  std::threads, contiguous blocks of faces (default 2)\n"
                "  --rate N     uniform Bfr::Tessellation rate (default 16)\n"
                "  --copies K   copies of the cage, offset along x (default: >= 50000 faces)\n"
                "  --repeat R   timed tessellation passes (default 5); the median is reported\n"
                "  --float      evaluate with Bfr::Surface<float> (default: double)\n"
                "  --adaptive-rates FILE  per-face rates, one line per face of the\n"
                "               replicated cage, instead of --rate\n"
                "  --scheme loop|catmark  the subdivision scheme (default: loop if the file\n"
                "               name starts with 'loop_', else catmark)\n");
    std::exit(0);
}

}  // namespace

int main(int argc, char **argv) {
    Args args;
    auto intArg = [&](int &i, const char *name, long lo, long hi) {
        if (i + 1 >= argc) badArgs(std::string(name) + " needs a value");
        long v;
        if (!parseInt(argv[i + 1], v) || v < lo || v > hi)
            badArgs(std::string(name) + " must be an integer in " + std::to_string(lo) + ".." +
                  std::to_string(hi) + ", not '" + argv[i + 1] + "'");
        ++i;
        return (int)v;
    };
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--threads") args.threads = intArg(i, "--threads", 1, 1024);
        else if (a == "--rate") args.rate = intArg(i, "--rate", 1, kMaxRate);
        else if (a == "--copies") args.copies = intArg(i, "--copies", 1, 1000000);
        else if (a == "--repeat") args.repeat = intArg(i, "--repeat", 1, 1000);
        else if (a == "--float") args.useFloat = true;
        else if (a == "--scheme") {
            if (i + 1 >= argc) badArgs("--scheme needs a value");
            args.scheme = argv[++i];
            if (args.scheme != "loop" && args.scheme != "catmark")
                badArgs("--scheme must be loop or catmark, not '" + args.scheme + "'");
        }
        else if (a == "--adaptive-rates") {
            if (i + 1 >= argc) badArgs("--adaptive-rates needs a value");
            args.ratesPath = argv[++i];
        } else if (a == "-h" || a == "--help") help();
        else if (!a.empty() && a[0] == '-') badArgs("unknown option '" + a + "'");
        else if (args.path.empty()) args.path = a;
        else badArgs("more than one cage given ('" + args.path + "', '" + a + "')");
    }
    if (args.path.empty()) badArgs("no cage given");
    g_path = args.path;

    std::string base = args.path.substr(
        args.path.find_last_of('/') == std::string::npos ? 0 : args.path.find_last_of('/') + 1);
    bool loop = args.scheme.empty() ? base.rfind("loop_", 0) == 0 : args.scheme == "loop";
    Sdc::SchemeType scheme = loop ? Sdc::SCHEME_LOOP : Sdc::SCHEME_CATMARK;

    Far::SetErrorCallback(farError);
    Far::SetWarningCallback(farWarning);

    Cage one = readCage(args.path);
    if (scheme == Sdc::SCHEME_LOOP) {
        for (int f = 0; f < one.numFaces(); ++f)
            if (one.faceSizes[f] != 3)
                die("face " + std::to_string(f) + " has " + std::to_string(one.faceSizes[f]) +
                    " vertices; the Loop scheme needs triangles");
    }
    if (args.copies == 0) args.copies = std::max(1, (50000 + one.numFaces() - 1) / one.numFaces());
    const long maxInt = std::numeric_limits<int>::max();
    if ((long)one.numFaces() * args.copies > maxInt / 64 ||
        (long)one.faceVerts.size() * args.copies > maxInt / 64 ||
        (long)one.numVertices() * args.copies > maxInt / 64)
        badArgs("--copies " + std::to_string(args.copies) + " makes too large a cage");
    Cage cage = replicate(one, args.copies);
    Topology topo = applyTags(cage, scheme);
    return args.useFloat ? run<float>(cage, topo, args) : run<double>(cage, topo, args);
}
