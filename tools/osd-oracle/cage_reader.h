// cage_reader.h: the OBJ + OpenSubdiv tag reader shared by osd_oracle.cpp and
// bfr_bench.cpp (test tools, not part of tessera).
//
// Included inside each program's anonymous namespace, after the standard and OpenSubdiv
// headers and after the program's own die() and warn() diagnostics, which it calls; it
// includes nothing itself.


struct Tag {
    std::string name;
    std::vector<int> ints;
    std::vector<float> floats;
    std::vector<std::string> strings;
    int line = 0;
};

struct Cage {
    std::vector<double> pos;     // 3 per vertex
    std::vector<int> faceSizes;  // vertices per face
    std::vector<int> faceVerts;  // 0-based vertex indices, concatenated
    std::vector<Tag> tags;
    int numVertices() const { return (int)(pos.size() / 3); }
    int numFaces() const { return (int)faceSizes.size(); }
};

bool parseInt(const std::string &s, long &out) {
    if (s.empty()) return false;
    char *end = nullptr;
    errno = 0;
    long v = std::strtol(s.c_str(), &end, 10);
    if (errno || *end != '\0') return false;
    out = v;
    return true;
}

bool parseDouble(const std::string &s, double &out) {
    if (s.empty()) return false;
    char *end = nullptr;
    errno = 0;
    double v = std::strtod(s.c_str(), &end);
    if (errno || *end != '\0' || !std::isfinite(v)) return false;
    out = v;
    return true;
}

// OBJ subset: "v x y z [w]", "f a b c ..." with corners "v", "v/vt", "v//vn",
// "v/vt/vn" (1-based, negative = relative), "t name ni/nf/ns ints floats
// strings" (OpenSubdiv's tag dialect, 0-based indices). vt, vn, vp, g, o, s,
// usemtl, mtllib, l, p and comments are ignored.
Cage readCage(const std::string &path) {
    std::ifstream in(path);
    if (!in) die("cannot open file");
    Cage cage;
    std::string line;
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream ls(line);
        std::string kw;
        if (!(ls >> kw) || kw[0] == '#') continue;
        auto bad = [&](const std::string &what) {
            die("line " + std::to_string(lineNo) + ": " + what + ": '" + line + "'");
        };
        if (kw == "v") {
            std::string tok;
            double xyz[3];
            for (int k = 0; k < 3; ++k) {
                if (!(ls >> tok) || !parseDouble(tok, xyz[k])) bad("bad vertex");
            }
            cage.pos.insert(cage.pos.end(), xyz, xyz + 3);
        } else if (kw == "f") {
            std::string tok;
            int n = 0;
            while (ls >> tok) {
                std::string first = tok.substr(0, tok.find('/'));
                long idx;
                if (!parseInt(first, idx) || idx == 0) bad("bad face corner '" + tok + "'");
                long nv = cage.numVertices();
                long v0 = idx > 0 ? idx - 1 : nv + idx;
                if (v0 < 0 || v0 >= nv) bad("face index out of range");
                cage.faceVerts.push_back((int)v0);
                ++n;
            }
            if (n < 3) bad("face with fewer than 3 vertices");
            cage.faceSizes.push_back(n);
        } else if (kw == "t") {
            Tag t;
            t.line = lineNo;
            std::string counts;
            if (!(ls >> t.name >> counts)) bad("bad tag");
            int ni, nf, ns;
            char c1, c2;
            std::istringstream cs(counts);
            if (!(cs >> ni >> c1 >> nf >> c2 >> ns) || c1 != '/' || c2 != '/' || ni < 0 ||
                nf < 0 || ns < 0)
                bad("bad tag counts");
            std::string tok;
            for (int k = 0; k < ni; ++k) {
                long v;
                if (!(ls >> tok) || !parseInt(tok, v)) bad("bad tag integer");
                t.ints.push_back((int)v);
            }
            for (int k = 0; k < nf; ++k) {
                double v;
                if (!(ls >> tok) || !parseDouble(tok, v)) bad("bad tag float");
                t.floats.push_back((float)v);
            }
            for (int k = 0; k < ns; ++k) {
                if (!(ls >> tok)) bad("bad tag string");
                t.strings.push_back(tok);
            }
            cage.tags.push_back(t);
        }
        // everything else ignored
    }
    if (in.bad()) die("read error");
    if (cage.numVertices() == 0) die("no vertices ('v' lines)");
    if (cage.numFaces() == 0) die("no faces ('f' lines)");
    return cage;
}

// ---------------------------------------------------------------------------
// Tags -> Sdc options and Far topology tags, as OpenSubdiv's regression tools
// interpret them (regression/common/far_utils.h: GetSdcOptions and
// TopologyRefinerFactory<Shape>::assignComponentTags).

struct Topology {
    Sdc::SchemeType scheme = Sdc::SCHEME_CATMARK;
    Sdc::Options options;
    std::vector<int> creasePairs;
    std::vector<float> creaseWeights;
    std::vector<int> corners;
    std::vector<float> cornerWeights;
    std::vector<int> holes;
};

const char *boundaryName(Sdc::Options::VtxBoundaryInterpolation b) {
    switch (b) {
    case Sdc::Options::VTX_BOUNDARY_NONE: return "none";
    case Sdc::Options::VTX_BOUNDARY_EDGE_ONLY: return "edge-only";
    case Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER: return "edge-and-corner";
    }
    return "?";
}

const char *schemeName(Sdc::SchemeType s) {
    switch (s) {
    case Sdc::SCHEME_BILINEAR: return "bilinear";
    case Sdc::SCHEME_CATMARK: return "catmark";
    case Sdc::SCHEME_LOOP: return "loop";
    }
    return "?";
}

Topology applyTags(const Cage &cage, Sdc::SchemeType scheme) {
    Topology topo;
    topo.scheme = scheme;
    // Regression-tool defaults (not Sdc::Options' own VTX_BOUNDARY_NONE).
    topo.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    topo.options.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
    topo.options.SetTriangleSubdivision(Sdc::Options::TRI_SUB_CATMARK);
    // Face-varying data is not used; left at Sdc's default.

    const int nv = cage.numVertices(), nf = cage.numFaces();
    for (const Tag &t : cage.tags) {
        std::string at = "tag '" + t.name + "' on line " + std::to_string(t.line);
        auto sharp = [&](size_t k) {
            float s = t.floats.size() > 1 ? t.floats[k] : t.floats[0];
            return s < 0.0f ? 0.0f : s;
        };
        if (t.name == "crease") {
            if (t.ints.size() < 2 || t.ints.size() % 2 || t.floats.empty() ||
                (t.floats.size() > 1 && t.floats.size() != t.ints.size() / 2))
                die(at + ": expects vertex pairs and 1 or one-per-edge sharpness");
            for (size_t j = 0; j + 1 < t.ints.size(); j += 2) {
                int a = t.ints[j], b = t.ints[j + 1];
                if (a < 0 || a >= nv || b < 0 || b >= nv) die(at + ": vertex out of range");
                // OpenSubdiv's regression reader indexes floats by j (the
                // pair's first int); with one float per edge that reads
                // past the pairs. Our cages carry one float per tag line.
                topo.creasePairs.push_back(a);
                topo.creasePairs.push_back(b);
                topo.creaseWeights.push_back(sharp(j / 2));
            }
        } else if (t.name == "corner") {
            if (t.ints.empty() || t.floats.empty() ||
                (t.floats.size() > 1 && t.floats.size() != t.ints.size()))
                die(at + ": expects vertices and 1 or one-per-vertex sharpness");
            for (size_t j = 0; j < t.ints.size(); ++j) {
                if (t.ints[j] < 0 || t.ints[j] >= nv) die(at + ": vertex out of range");
                topo.corners.push_back(t.ints[j]);
                topo.cornerWeights.push_back(sharp(j));
            }
        } else if (t.name == "hole") {
            for (int f : t.ints) {
                if (f < 0 || f >= nf) die(at + ": face out of range");
                topo.holes.push_back(f);
            }
        } else if (t.name == "interpolateboundary") {
            if (t.ints.size() != 1) die(at + ": expects 1 integer");
            // NB: the tag integers are NOT the Sdc enum values.
            switch (t.ints[0]) {
            case 0: topo.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_NONE); break;
            case 1: topo.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER); break;
            case 2: topo.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY); break;
            default: die(at + ": unknown value " + std::to_string(t.ints[0]));
            }
        } else if (t.name == "creasemethod") {
            if (t.strings.size() != 1) die(at + ": expects 1 string");
            if (t.strings[0] == "normal") topo.options.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
            else if (t.strings[0] == "chaikin") topo.options.SetCreasingMethod(Sdc::Options::CREASE_CHAIKIN);
            else die(at + ": expects 'normal' or 'chaikin'");
        } else if (t.name == "smoothtriangles") {
            if (t.strings.size() != 1) die(at + ": expects 1 string");
            if (scheme != Sdc::SCHEME_CATMARK) {
                warn(at + ": only applies to Catmark, ignored");
                continue;
            }
            if (t.strings[0] == "catmark") topo.options.SetTriangleSubdivision(Sdc::Options::TRI_SUB_CATMARK);
            else if (t.strings[0] == "smooth") topo.options.SetTriangleSubdivision(Sdc::Options::TRI_SUB_SMOOTH);
            else die(at + ": expects 'catmark' or 'smooth'");
        } else {
            warn(at + ": unknown tag, ignored");
        }
    }
    return topo;
}

// The Far::TopologyRefiner of a cage and its tags (dies when OpenSubdiv refuses it).
Far::TopologyRefiner *createRefiner(const Cage &cage, const Topology &topo) {
    Far::TopologyDescriptor desc;
    desc.numVertices = cage.numVertices();
    desc.numFaces = cage.numFaces();
    desc.numVertsPerFace = cage.faceSizes.data();
    desc.vertIndicesPerFace = cage.faceVerts.data();
    desc.numCreases = (int)topo.creaseWeights.size();
    desc.creaseVertexIndexPairs = topo.creasePairs.data();
    desc.creaseWeights = topo.creaseWeights.data();
    desc.numCorners = (int)topo.cornerWeights.size();
    desc.cornerVertexIndices = topo.corners.data();
    desc.cornerWeights = topo.cornerWeights.data();
    desc.numHoles = (int)topo.holes.size();
    desc.holeIndices = topo.holes.data();

    typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;
    Far::TopologyRefiner *refiner =
        Factory::Create(desc, Factory::Options(topo.scheme, topo.options));
    if (!refiner) die("OpenSubdiv's TopologyRefinerFactory refused the topology");
    return refiner;
}
