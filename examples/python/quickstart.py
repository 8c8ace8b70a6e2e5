"""The README's five lines: the teapot within 0.1 % of its size, as numpy arrays and a file.

Run from the repository root, with the shared models beside it:
    python examples/python/quickstart.py
"""

import tessera

teapot = tessera.load("../shared/data/patches/teapot.patches")
mesh = tessera.tessellate(teapot, tolerance="0.1%")  # guaranteed within 0.1 % of the diagonal
print(mesh.vertices.shape, mesh.faces.shape, mesh.report["guaranteed_bound"])
mesh.write("teapot.glb")
