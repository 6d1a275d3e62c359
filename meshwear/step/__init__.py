"""The step and the run's loop (docs/model.md, "The step loop").

- :mod:`.simulate`: :func:`~.simulate.run` drives the steps and calls the
  observers; :func:`~.simulate.step_body` fixes the phase order of one step;
- :mod:`.stepper`: the compiled loop's Python side;
- :mod:`.counters`: the worn counter-surfaces' wear in a step;
- :mod:`.estimate`: what ``meshwear check`` says a run will take.

Imports every stage below it: the model, the long run (which the loop drives),
the outputs' observer interface and what those import.
"""
