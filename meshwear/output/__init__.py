"""What a run writes (docs/outputs.md), and what reads it back.

- observers the run calls: :mod:`.recorder` (the files of a run's folder),
  :mod:`.memory` (history in memory), with the fields of :mod:`.fields`;
- the files: :mod:`.tables` (``history.csv``, JSON), :mod:`.vtk` and
  :mod:`.vtkhdf` (the ParaView series), :mod:`.folder` (one run per folder);
- outputs inside a jumped span, filled from the jump: :mod:`.filled`;
- after a run: :mod:`.export` (worn parts as mesh files), :mod:`.plots` and
  :mod:`.maps` (``meshwear plot``).

Imports the stages below it (model, contact, surfaces, scene, kernels); never
the long run or the step, which call its observers.
"""
