"""The Python module's extract_surface cleans the design as the run does: the study's
optimization section decides whether closed internal voids are filled (fill_voids), as it does
for the run and for the worker's re-extraction (pipeline::reextraction). Before, the binding
filled every void whatever the section said."""
import json
import unittest

import numpy as np

import topopt

native = topopt.native()

CELLS = 8  # cells of 1 mm along each side of the block
VOID = range(2, 6)  # cells of the closed void inside it, along each axis (4 x 4 x 4 mm)


def block_with_a_void():
    """A CELLS^3 mm block of Kuhn tets (6 per cell, positive volume): nodes #V x 3, tets #T x 4
    and element densities #T, 1 everywhere but 0.001 in the VOID cells."""
    n = CELLS + 1
    nodes = np.array([[i, j, k] for k in range(n) for j in range(n) for i in range(n)], dtype=float)
    index = lambda i, j, k: i + n * (j + n * k)  # noqa: E731
    corner = lambda i, j, k, c: index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))  # noqa: E731
    paths = [(1, 3), (1, 5), (2, 3), (2, 6), (4, 5), (4, 6)]  # 0 -> a -> b -> 7 along the cube's edges
    tets, density = [], []
    for k in range(CELLS):
        for j in range(CELLS):
            for i in range(CELLS):
                for a, b in paths:
                    t = [corner(i, j, k, c) for c in (0, a, b, 7)]
                    if np.linalg.det(nodes[t[1:]] - nodes[t[0]]) < 0:
                        t[1], t[2] = t[2], t[1]
                    tets.append(t)
                    density.append(0.001 if i in VOID and j in VOID and k in VOID else 1.0)
    return nodes, np.array(tets, dtype=np.int64), np.array(density)


def enclosed_volume(points, triangles):
    """The signed volume enclosed by a closed outward triangle surface (an inner shell, a void,
    counts negative)."""
    a, b, c = (points[triangles[:, i]] for i in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


class Reextraction(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nodes, cls.tets, cls.density = block_with_a_void()
        cls.domain = np.zeros(len(cls.tets), dtype=np.int32)

    def extract(self, optimization):
        points, triangles = native.extract_surface(self.nodes, self.tets, self.domain, self.density, 0.5, -1.0, -1,
                                                   optimization)
        return enclosed_volume(np.asarray(points), np.asarray(triangles))

    def test_the_void_is_filled_by_default_and_kept_when_the_section_says(self):
        block = float(CELLS ** 3)
        filled = self.extract("")
        kept = self.extract(json.dumps({"fill_voids": False}))
        # filled: the whole block (the smoothing keeps its flat faces and corners within 1 %)
        self.assertAlmostEqual(filled, block, delta=0.01 * block)
        # kept: the block less a void between the 2 x 2 x 2 mm of nodes all in the void and the
        # 4 x 4 x 4 mm of its cells
        self.assertLess(kept, block - 8)
        self.assertGreater(kept, block - 64)
        # the hygiene at the same threshold says the same: one closed void, filled or kept
        self.assertEqual(native.design_report(self.nodes, self.tets, self.domain, self.density, 0.5)["voids_filled"], 1)
        report = native.design_report(self.nodes, self.tets, self.domain, self.density, 0.5, fill_voids=False)
        self.assertEqual(report["voids_kept"], 1)
        # its volume counts the void's tets (measured 54 mm³; the surface encloses 39.6 of it)
        self.assertGreater(report["void_volume_kept"], 8)


if __name__ == "__main__":
    unittest.main()
