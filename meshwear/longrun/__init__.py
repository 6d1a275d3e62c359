"""Long durations (docs/model.md, "Long durations"): cycle jumping with error
control, and checkpoints that let a long run stop and resume.

- :mod:`.wear`: the jumping run's controller and its state;
- :mod:`.jump_choice`: how many cycles to jump, and which bound set it;
- :mod:`.jump_errors`: the jumps' errors (drift, noise, slope), their
  relaxation by the contact, and the run's error estimate;
- :mod:`.jump_volume`: the volume a load-carrying body's jump wears;
- :mod:`.extrapolate`: taking a jump: the bodies and worn counter-parts
  moved on by its cycles;
- :mod:`.jumps`: one implicit (backward-Euler) jump and its error;
- :mod:`.jump_geometry`: what a jump may do to the mesh it moves;
- :mod:`.checkpoint`: save a running state atomically, and resume from it.

Imports the stages below it (outputs, model, contact, surfaces, motion,
kernels); never :mod:`meshwear.step`, which drives it.
"""
