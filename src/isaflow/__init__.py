"""isaflow: incremental static analysis of 2D flow by inter-colliding point particles.

Replication of Papadopoulos, Koutitas & Lazaridis (2016), Open J. Civil Eng. 6,
397-409.  Units throughout: length cm, force N, stiffness N/cm, time s.
"""

__version__ = "0.1.0"
