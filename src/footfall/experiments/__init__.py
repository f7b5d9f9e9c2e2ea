"""Experiments that run simulations and collect results: the section 5.5 comparisons (reduced-order
and MuJoCo), the benchmarks and the demo."""
