"""Contact models: how a vertex presses on a counter-surface (docs/model.md).

- :mod:`.winkler`: the Winkler (penalty) contact of one body, on the
  compiled :mod:`meshwear.kernels.contact`;
- :mod:`.elastic`: the elastic half-space model in a run (its step and
  what the run reads from it), on the solver of :mod:`.halfspace` and the
  grid fields of :mod:`.cellfields`; the patch and its grid around a
  contact are :mod:`.elastic_patch`'s, the friction (Cattaneo-Mindlin or
  Coulomb) :mod:`.elastic_friction`'s;
- :mod:`.stability`: the contact's bound on a stable time step.

Imports the stages below it (surfaces, motion, scene, geometry, kernels).
"""
