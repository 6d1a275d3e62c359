"""Long durations (docs/model.md, "Long durations"): cycle jumping with error
control, and checkpoints that let a long run stop and resume.

- :mod:`.wear`: the jumping run's controller, its state and its error;
- :mod:`.jumps`: one implicit (backward-Euler) jump and its error;
- :mod:`.jump_geometry`: what a jump may do to the mesh it moves;
- :mod:`.checkpoint`: save a running state atomically, and resume from it.

Imports the stages below it (outputs, model, contact, surfaces, motion,
kernels); never :mod:`meshwear.step`, which drives it.
"""
