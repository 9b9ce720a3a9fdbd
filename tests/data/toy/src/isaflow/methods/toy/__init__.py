"""A toy tank method (tests/test_add_a_method.py): a damped lattice of masses and springs in the first vessel,
stepped through the one run driver until it is at rest (isaflow.rest)."""

from .. import Method, Variant

METHOD = Method(name="toy", order=90, marker="x", tank=True, label="toy damped lattice",
                paper="toy_lattice", paper_label="A toy paper on a damped spring lattice (tests/data/toy)",
                variants=(Variant("damped", "toy: a square lattice of springs, damped, released under gravity",
                                  "tab:gray", "x"),))
