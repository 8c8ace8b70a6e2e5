"""Triangles against the measured maximum error for two schemes on one model: the picture
behind "adaptive needs fewer triangles for the same error" (needs matplotlib: `pip install
matplotlib`). Each point is one tolerance, its error measured against the exact surface
(`Mesh.measure_error`), not the certified bound.

Run from the repository root, with the shared models beside it:
    python examples/python/error_plot.py [MODEL] [-o error_plot.png]
"""

import argparse

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt

import tessera


def main():
    parser = argparse.ArgumentParser(description="triangles against measured error, uniform and transition")
    parser.add_argument("model", nargs="?", default="../shared/data/patches/teapot.patches")
    parser.add_argument("-o", "--output", default="error_plot.png")
    args = parser.parse_args()
    surface = tessera.load(args.model)
    for scheme in ["uniform", "transition"]:
        points = []
        for percent in [1, 0.5, 0.2, 0.1, 0.05, 0.02]:
            mesh = tessera.tessellate(surface, scheme=scheme, tolerance=f"{percent}%", corner_params=True)
            points.append((mesh.triangle_count, mesh.measure_error()["max"]))
            print(f"{scheme:>10} {percent:>5} %: {points[-1][0]:>7} triangles, max error {points[-1][1]:.3e}")
        plt.loglog(*zip(*points), marker="o", label=scheme)
    plt.xlabel("triangles")
    plt.ylabel("measured max error (model units)")
    plt.title(f"{args.model.split('/')[-1]}: triangles against measured error")
    plt.legend()
    plt.grid(True, which="both", alpha=0.3)
    plt.savefig(args.output, dpi=120, bbox_inches="tight")
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
