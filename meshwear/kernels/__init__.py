"""Compiled kernels (numba), the bottom stage: plain arrays in and out.

The contact, friction and wear of a body's vertices (:mod:`.contact`, the
laws of :mod:`.laws`), the planes under them (:mod:`.counter`,
:mod:`.analytic`, the face lookups of :mod:`.nearest` on the tree of
:mod:`.tree`), a worn counter's wear (:mod:`.counter_wear`), rigid-body and
quasi-static steps (:mod:`.rigid`, :mod:`.balance`, :mod:`.turn_balance`),
the step loops (:mod:`.loop`, :mod:`.mechanism`), the half-space gaps
(:mod:`.elastic`), where a moving surface is (:mod:`.frames`), and the cache
they compile into (:mod:`.jit`, :mod:`.cachedir`, :mod:`.notice`).

Imports no other stage of meshwear: every kernel has a numpy twin in the tests.
"""
