"""Pictures of Langur programs (the ``plot`` extra: matplotlib and pyvista; ``langur`` never
imports this package).

* :mod:`viz.geometry` — the numbers: the integrand, the regular part of its derivative and its
  deltas (spikes in one variable, ridges along the zero set in two), from the engines' output;
* :mod:`viz.curves` — one-variable programs with matplotlib (paper Fig. 1);
* :mod:`viz.flat` — two-variable programs seen from above, and Monte Carlo convergence;
* :mod:`viz.surfaces` — two-variable programs as pyvista surfaces with the delta ridge (Fig. 9);
* :mod:`viz.risk` — the risk minimization of §2 (Fig. 2 and 3).
"""
