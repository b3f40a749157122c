"""PyPdController: the quaternion PD attitude law of PdController (error_law = 0, gain_mode = 0) as a
PythonFMU (package `pythonfmu`, pinned in requirements.txt), a "foreign" unit for the bring-your-own-unit
tests. Built by tests/foreign_units.py with `python -m pythonfmu build -f PyPdController.py`.

    q_E = conj(q) (x) q_ref,  e = 2 q_E,w q_E,v,  T_i = k_i e_i + k_d,i w_i,
    k_i = wn^2 I_i,  k_d,i = -2 zeta wn I_i

Plain Python (no numpy): the FMU needs nothing but the interpreter that loads it. The outputs are
computed by their getters from the inputs currently set (direct feedthrough, like PdController): PythonFMU
otherwise returns attribute values that only change in do_step. PythonFMU 0.7.0 writes no units;
foreign_units.build_python_pd(units=True) adds ours to the modelDescription after the build.
"""

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real

INPUTS = ("q_w", "q_x", "q_y", "q_z", "w_x", "w_y", "w_z",
          "q_ref_w", "q_ref_x", "q_ref_y", "q_ref_z", "w_ref_x", "w_ref_y", "w_ref_z")
PARAMETERS = {"wn": 1.0, "zeta": 1.0, "inertia_xx": 1000.0, "inertia_yy": 500.0, "inertia_zz": 700.0}


class PyPdController(Fmi2Slave):
    author = "spacecraft_fmus tests"
    description = "Quaternion PD attitude controller written with PythonFMU (a foreign unit for the tests)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        for name in INPUTS:
            setattr(self, name, 1.0 if name in ("q_w", "q_ref_w") else 0.0)
            self.register_variable(Real(name, causality=Fmi2Causality.input,
                                        variability=Fmi2Variability.continuous))
        for i, axis in enumerate("xyz"):
            self.register_variable(Real(f"torque_cmd_{axis}", causality=Fmi2Causality.output,
                                        variability=Fmi2Variability.continuous,
                                        getter=lambda i=i: self.torque()[i]))
        for name, value in PARAMETERS.items():
            setattr(self, name, value)
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed))

    def torque(self):
        qw, qx, qy, qz = self.q_w, -self.q_x, -self.q_y, -self.q_z  # conj(q)
        rw, rx, ry, rz = self.q_ref_w, self.q_ref_x, self.q_ref_y, self.q_ref_z
        ew = qw * rw - qx * rx - qy * ry - qz * rz
        ex = qw * rx + rw * qx + (qy * rz - qz * ry)
        ey = qw * ry + rw * qy + (qz * rx - qx * rz)
        ez = qw * rz + rw * qz + (qx * ry - qy * rx)
        e = (2.0 * ew * ex, 2.0 * ew * ey, 2.0 * ew * ez)
        w = (self.w_x, self.w_y, self.w_z)
        inertia = (self.inertia_xx, self.inertia_yy, self.inertia_zz)
        return [self.wn * self.wn * inertia[i] * e[i] + inertia[i] * (-2.0 * self.zeta * self.wn) * w[i]
                for i in range(3)]

    def do_step(self, current_time, step_size):
        return True
