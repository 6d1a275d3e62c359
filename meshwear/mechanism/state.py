"""A mechanism's state and its reports: MuJoCo's start (the keyframe, the
controls), a reset, the clock moved by a cycle jump, its whole integration
state for checkpoints (docs/outputs.md, "Checkpoints and ``--resume``"), its
state at a phase shown for outputs filled from a jump, its ``history.csv``
columns (docs/outputs.md, "``history.csv``") and its lines for ``meshwear
check``. :class:`StateAndReports` is a part of
:class:`meshwear.mechanism.build.Mechanism` and works on what that sets up:
chiefly MuJoCo's ``model`` and ``data``, the ``keyframe`` and ``controls``,
the riders and their placing (``place``), and the data of a phase shown
(``shown``).
"""

import numpy as np


class StateAndReports:
    """MuJoCo's state set and read, and the mechanism's reports (a part of
    :class:`~meshwear.mechanism.build.Mechanism`)."""

    def _start(self):
        mujoco, m, d = self.mujoco, self.model, self.data
        d.warning[self._bad_acceleration].number = 0
        if self.keyframe is None:
            mujoco.mj_resetData(m, d)
        else:
            mujoco.mj_resetDataKeyframe(m, d, self.keyframe)
        for a, value in self.controls:
            d.ctrl[a] = value
        mujoco.mj_forward(m, d)

    def reset(self, model, state):
        """MuJoCo back at its initial state (the keyframe, or the model's
        reference pose at rest), the controls set, the riders there; the
        bodies' active sets on trial again."""
        self._start()
        object.__setattr__(model, "cull", True)
        self.refs = None
        self.failed, self.due = None, True
        self.place(model, state, 0.0)

    def jumped(self, model, state, duration):
        """A cycle jump moved meshwear's clock by ``duration`` (whole cycles):
        MuJoCo's with it, its state otherwise that of the end of the resolved
        cycle, the riders placed at the new time."""
        self.data.time += duration
        self.place(model, state, state.time)

    def show(self, model, state, values=None):
        """For outputs filled from a jump (:mod:`meshwear.output.filled`):
        the riders of ``state``, the surfaces on its bodies and the joint
        columns where MuJoCo had them at the phase of ``values`` (a
        :meth:`get_state`), placed at ``state.time``; None: back where its
        own data has them. Its own data is left alone (:meth:`set_state`'s
        forward pass would change the next step's warm start)."""
        mujoco, m = self.mujoco, self.model
        self.shown = None
        if values is not None:
            if self._phase is None:
                self._phase = mujoco.MjData(m)
            mujoco.mj_setState(m, self._phase, np.asarray(values, float),
                               mujoco.mjtState.mjSTATE_INTEGRATION)
            mujoco.mj_forward(m, self._phase)
            self.shown = self._phase
        self.place(model, state, state.time)

    def get_state(self):
        """MuJoCo's whole integration state (time, qpos, qvel, act, ...)."""
        mujoco = self.mujoco
        kind = mujoco.mjtState.mjSTATE_INTEGRATION
        out = np.zeros(mujoco.mj_stateSize(self.model, kind))
        mujoco.mj_getState(self.model, self.data, out, kind)
        return out

    def set_state(self, values, model, state):
        mujoco, m, d = self.mujoco, self.model, self.data
        mujoco.mj_setState(m, d, np.asarray(values, float), mujoco.mjtState.mjSTATE_INTEGRATION)
        mujoco.mj_forward(m, d)
        self.place(model, state, state.time)

    def columns(self):
        """Its ``history.csv`` columns now (:meth:`joints`)."""
        return self.joints()

    def joints(self):
        """History columns of the mechanism (docs/outputs.md): each hinge and
        slide joint's position and velocity (``<joint>.q``, ``<joint>.v``)
        and each actuator's force (``<actuator>.force``); ball and free
        joints are in the rows of the parts they carry."""
        m, d = self.model, self.data if self.shown is None else self.shown
        out = {}
        kinds = (int(self.mujoco.mjtJoint.mjJNT_HINGE), int(self.mujoco.mjtJoint.mjJNT_SLIDE))
        for j in range(m.njnt):
            if int(m.jnt_type[j]) not in kinds:
                continue
            name = m.joint(j).name or f"joint{j}"
            out[f"{name}.q"] = float(d.qpos[m.jnt_qposadr[j]])
            out[f"{name}.v"] = float(d.qvel[m.jnt_dofadr[j]])
        for a in range(m.nu):
            name = m.actuator(a).name or f"actuator{a}"
            out[f"{name}.force"] = float(d.actuator_force[a])
        return out

    def describe(self, model, state):
        """Lines for ``meshwear check``: the MuJoCo model, its joints and
        actuators, the parts meshwear handles on its bodies, the stability
        limits of their contact (every vertex; those within reach of a
        surface in ``state``, the run's start)."""
        m = self.model
        mujoco = self.mujoco
        kinds = {int(v): k.removeprefix("mjJNT_").lower()
                 for k, v in mujoco.mjtJoint.__members__.items()}
        joints = ", ".join(f"{m.joint(j).name or j} ({kinds.get(int(m.jnt_type[j]), '?')})"
                           for j in range(m.njnt)) or "none"
        actuators = ", ".join(m.actuator(a).name or str(a) for a in range(m.nu)) or "none"
        riders = {}
        for _, i, name, _ in self.bodies:
            riders.setdefault(name, []).append(model.bodies[i].name)
        for surface, _, name, _ in self.surfaces:
            riders.setdefault(name, []).append(surface.name)
        lines = [f"mechanism {self.path.name}: {m.nbody - 1} bodies, {m.njnt} joints "
                 f"[{joints}], actuators [{actuators}]"]
        for name, parts in riders.items():
            lines.append(f"  body {name!r} ({self.mass(name):.6g} kg) carries "
                         + ", ".join(repr(p) for p in parts))
        contact, _ = self.stable_limit(model.bodies, model.law, model.slots)
        reach, _ = self.watched_limit(model, state)
        lines.append(f"  MuJoCo timestep in the file {self.file_timestep:.3g} s; the coupled "
                     f"step {model.dt:.3g} s; the riders' contact in the joints is stable up to "
                     f"{contact:.3g} s with every vertex pressing at once, {reach:.3g} s with "
                     "the vertices within reach of a surface at the start (a run.dt between "
                     "the two is checked at every active-set refresh)")
        return lines
