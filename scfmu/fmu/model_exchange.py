"""The Model Exchange integration of :class:`scfmu.fmu.Fmu`: event iteration, the states and derivatives,
SciPy's ``solve_ivp`` (or a fixed-step RK4 with bisection on event indicators) between communication
points, time and state events."""

from __future__ import annotations

import numpy as np

from ..binding import as_doubles


class ModelExchange:
    """Mixin of :class:`scfmu.fmu.Fmu` for ``interface="me"``: uses its ``slave`` (FMU2Model / FMU3Model),
    ``fmi``, ``model``, ``nx``, ``nz``, ``next_event``, ``time`` and the ``me_*`` solver settings."""

    def _event_iteration(self) -> None:
        while True:
            if self.fmi == 2:
                needed, terminate, _, _, defined, t_next = self.slave.newDiscreteStates()
            else:
                needed, terminate, _, _, defined, t_next = self.slave.updateDiscreteStates()
            if terminate:
                raise RuntimeError(f"{self.model}: the unit asked to terminate at t = {self.time}")
            if not needed:
                break
        self.next_event = t_next if defined else None

    def _states(self) -> np.ndarray:
        x = np.zeros(self.nx)
        if self.nx:
            self.slave.getContinuousStates(as_doubles(x), self.nx)
        return x

    def _rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        x = np.ascontiguousarray(x, dtype=float)
        self.slave.setTime(t)
        self.slave.setContinuousStates(as_doubles(x), self.nx)
        dx = np.zeros(self.nx)
        if self.fmi == 2:
            self.slave.getDerivatives(as_doubles(dx), self.nx)
        else:
            self.slave.getContinuousStateDerivatives(as_doubles(dx), self.nx)
        return dx

    def _indicators(self) -> np.ndarray:
        z = np.zeros(self.nz)
        if self.nz:
            self.slave.getEventIndicators(as_doubles(z), self.nz)
        return z

    def _state_events(self):
        """solve_ivp event functions, one per event indicator: a sign change stops the integration."""
        def ev(i):
            def f(t, x):
                self._rhs(t, x)
                return self._indicators()[i]
            f.terminal = True
            return f
        return [ev(i) for i in range(self.nz)]

    def _rk4(self, t: float, x: np.ndarray, h: float, k1: np.ndarray) -> np.ndarray:
        k2 = self._rhs(t + 0.5 * h, x + 0.5 * h * k1)
        k3 = self._rhs(t + 0.5 * h, x + 0.5 * h * k2)
        k4 = self._rhs(t + h, x + h * k3)
        return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)

    def _rk4_interval(self, t: float, t_stop: float, dt: float, eps: float) -> tuple[float, bool]:
        """Fixed-step RK4 from t towards t_stop; stops early at a state event or when the unit asks for an
        event after ``completedIntegratorStep``. Returns (time reached, event to handle)."""
        h_fix = min(self.me_max_step, dt) if self.me_max_step > 0 else dt
        x = self._states()
        z = self._indicators() if self.nz else None
        while t < t_stop - eps:
            h = min(h_fix, t_stop - t)
            if t + h > t_stop - eps:
                h = t_stop - t
            k1 = self._rhs(t, x)
            xn = self._rk4(t, x, h, k1)
            tn = t_stop if abs(t + h - t_stop) <= eps else t + h
            self._rhs(tn, xn)
            crossed = False
            if self.nz:
                zn = self._indicators()
                crossed = bool(np.any((z > 0) != (zn > 0)))
                if crossed:  # bisection on the step size
                    lo, hi, x_hi = 0.0, 1.0, xn
                    while (hi - lo) * h > eps:
                        mid = 0.5 * (lo + hi)
                        xm = self._rk4(t, x, mid * h, k1)
                        self._rhs(t + mid * h, xm)
                        if np.any((z > 0) != (self._indicators() > 0)):
                            hi, x_hi = mid, xm
                        else:
                            lo = mid
                    tn, xn = t + hi * h, x_hi
                    self._rhs(tn, xn)
                else:
                    z = zn
            t, x = tn, xn
            enter, terminate = self.slave.completedIntegratorStep()
            if terminate:
                raise RuntimeError(f"{self.model}: the unit asked to terminate at t = {t}")
            if crossed or enter:
                return t, True
        return t, False

    def _me_step(self, t: float, dt: float) -> None:
        t_end = t + dt
        eps = 1e-12 * max(1.0, abs(t_end))
        events = self._state_events() if self.nz else None
        while t < t_end - eps:
            t_stop = t_end if self.next_event is None or self.next_event >= t_end - eps else self.next_event
            state_event = False
            if self.me_method == "RK4" and self.nx:
                t_stop, event = self._rk4_interval(t, t_stop, dt, eps)
                at_event = self.next_event is not None and abs(t_stop - self.next_event) <= eps
                if event or at_event:
                    self.time = t_stop
                    self.slave.enterEventMode()
                    self._event_iteration()
                    self.slave.enterContinuousTimeMode()
                t = t_stop
                continue
            if self.nx:
                from scipy.integrate import solve_ivp  # imported here: SciPy costs ~1 s at start-up
                x0 = self._states()
                sol = solve_ivp(self._rhs, (t, t_stop), x0, method=self.me_method,
                                rtol=self.me_rtol, atol=self.me_atol, events=events)
                if not sol.success:
                    raise RuntimeError(f"{self.model}: solve_ivp failed from t = {t} to {t_stop}: {sol.message}")
                if sol.status == 1 and float(sol.t[-1]) <= t + eps:
                    # a root at the interval's start: the indicator is (to rounding) 0 at t, which solve_ivp
                    # takes as a sign change at once, and the unit saw none at t. Step just past t without
                    # event functions and hand the event to the unit there, where the sign has changed;
                    # never stop at t again (that looped for ever)
                    t_stop = min(t_stop, t + 1000.0 * eps)
                    sol = solve_ivp(self._rhs, (t, t_stop), x0, method=self.me_method,
                                    rtol=self.me_rtol, atol=self.me_atol)
                    if not sol.success:
                        raise RuntimeError(f"{self.model}: solve_ivp failed from t = {t} to {t_stop}: {sol.message}")
                    state_event = True
                elif sol.status == 1:  # an event indicator changed sign: stop there
                    state_event, t_stop = True, float(sol.t[-1])
                self._rhs(t_stop, sol.y[:, -1])  # leaves the unit at (t_stop, x(t_stop))
            else:
                self.slave.setTime(t_stop)
            enter, terminate = self.slave.completedIntegratorStep()
            if terminate:
                raise RuntimeError(f"{self.model}: the unit asked to terminate at t = {t_stop}")
            at_event = self.next_event is not None and abs(t_stop - self.next_event) <= eps
            if enter or at_event or state_event:
                self.time = t_stop
                self.slave.enterEventMode()
                self._event_iteration()
                self.slave.enterContinuousTimeMode()
            t = t_stop
