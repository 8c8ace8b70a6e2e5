#!/usr/bin/env python3
"""Compare two osd_oracle-format outputs face by face.

usage: compare.py REFERENCE.txt CANDIDATE.txt [--cage CAGE.obj] [--tol 1e-6]

Both files are in the format of osd_oracle (README.md). Faces must match in
count, vertex count and point count, and points must have the same (u, v)
within 1e-12. The position error is reported relative to the bounding-box
diagonal of the cage's vertices (--cage), or, without it, of the reference
points. Exit status 0 if the largest relative error is <= --tol, 1 if not,
2 on a structural mismatch.
"""
import math
import sys


def read(path):
    faces = {}
    cur = None
    with open(path) as f:
        for line in f:
            w = line.split()
            if not w or w[0].startswith('#'):
                continue
            if w[0] == 'face':
                cur = []
                faces[int(w[1])] = (int(w[3]), int(w[5]), cur)
            elif w[0] == 'facets':
                cur = None  # skip the triangle lines that follow
            elif cur is not None:
                cur.append([float(x) for x in w])
    return faces


def bbox_diag(points):
    lo = [min(p[k] for p in points) for k in range(3)]
    hi = [max(p[k] for p in points) for k in range(3)]
    return math.dist(lo, hi)


def main(argv):
    args, cage, tol = [], None, 1e-6
    i = 1
    while i < len(argv):
        if argv[i] == '--cage':
            cage = argv[i + 1]; i += 2
        elif argv[i] == '--tol':
            tol = float(argv[i + 1]); i += 2
        else:
            args.append(argv[i]); i += 1
    if len(args) != 2:
        print(__doc__, file=sys.stderr)
        return 64
    ref, cand = read(args[0]), read(args[1])
    if cage:
        with open(cage) as f:
            pts = [[float(x) for x in l.split()[1:4]] for l in f if l.startswith('v ')]
    else:
        pts = [p[2:5] for (_, _, ps) in ref.values() for p in ps]
    diag = bbox_diag(pts) if pts else 1.0
    if set(ref) != set(cand):
        print('face sets differ: only in reference %s, only in candidate %s' % (
            sorted(set(ref) - set(cand))[:10], sorted(set(cand) - set(ref))[:10]))
        return 2
    worst, worst_at = 0.0, None
    for f in sorted(ref):
        k1, m1, p1 = ref[f]
        k2, m2, p2 = cand[f]
        if (k1, m1) != (k2, m2) or len(p1) != len(p2):
            print('face %d: vertices/points %d/%d vs %d/%d' % (f, k1, m1, k2, m2))
            return 2
        for j, (a, b) in enumerate(zip(p1, p2)):
            if abs(a[0] - b[0]) > 1e-12 or abs(a[1] - b[1]) > 1e-12:
                print('face %d point %d: (u,v) %r vs %r' % (f, j, a[:2], b[:2]))
                return 2
            e = math.dist(a[2:5], b[2:5]) / diag
            if e > worst:
                worst, worst_at = e, (f, j, a[0], a[1])
    where = '' if worst_at is None else ' at face %d point %d (u,v)=(%g,%g)' % worst_at
    print('faces %d diag %.6g max_rel_err %.3e%s %s' % (
        len(ref), diag, worst, where, 'OK' if worst <= tol else 'FAIL'))
    return 0 if worst <= tol else 1


if __name__ == '__main__':
    sys.exit(main(sys.argv))
