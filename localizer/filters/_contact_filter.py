"""Sequential localization while rolling: the exact grid filter over the start of the rolling.

The jaw rolls on a convex stretch of the part; with the contact at arc position σ₀ when the rolling
starts, the measured rotations fix the whole path, and what the wrist measures along the way, the
contact's travel turned into arc, tells the starts apart. The hypotheses are the starts on a grid over
the whole boundary; every nuisance of the error model is weighed out in closed form, so one reading
costs a few vector operations on the grid. The model and why each rule is as it is: docs/filter.md.

The filter is built in layers, each a class over the one below:
:class:`~localizer.filters._contact_state.ContactState` (settings, grid, running sums),
:class:`~localizer.filters._contact_marginal.ContactMarginal` (the evidence and the posterior),
:class:`~localizer.filters._contact_fit.ContactFit` (stretches of readings: the fit test) and
:class:`ContactFilter` here (readings in, a belief out).
"""

from __future__ import annotations

import math

import numpy as np

from .._defaults import BRIDGE_JUMP
from .._errors import QueryError
from ._belief import Belief, belief_flags, most_probable
from ._contact_fit import ContactFit
from ._contact_settings import (
    BRIDGE_MISS,
    CONTRADICTION,
    LOOKALIKE_RADIUS,
    TURN_MARGIN,
)
from ._stretches import (
    FIT_EVERY,
    FIT_MIN_READINGS,
    FIT_STARTS,
    MAX_QUARANTINE,
    NOISE_FIT_LIMIT,
    UNEXPLAINED,
    Misfit,
)

__all__ = ["ContactFilter"]


class ContactFilter(ContactFit):
    """Exact Bayesian filter over the start of the rolling, on a grid (see the docs/filter.md).

    Parameters
    ----------
    part : Part or Outline
    spacing : float, mm
        Grid step of the hypotheses (default 0.02 mm, 1/15 of the paper's 0.3 mm radius).
    sd_position : float, mm
        Standard deviation of one contact-location reading, as arc.
    sd_scale : float
        Standard deviation of the relative scale of the measured arcs against the model's: the
        calibration's and the part's own size (default :data:`SCALE_SD`, 1.04%; 0: none).
    sd_slope : float, rad
        Standard deviation of the B-spline coefficients of the part's slope error
        against its model (0: a perfect part). :func:`sim2d.machining_slope` gives it for
        the simulator's machining model.
    shape_spacing : float, mm
        Knot spacing of that B-spline basis, in cumulative arc.
    radius : float, mm
        Success radius of :meth:`belief`.
    mode_floor : float
        Probability a mode needs to count in ``ambiguous``.
    confidence : float
        Probability the leading mode needs for the belief not to be ``ambiguous``.
    prune : float
        Hypotheses this many nats below the best are no longer evaluated (with a slope envelope:
        below the best under every prior of it, judged at each :meth:`belief`; pruned under the
        slope prior alone, a start that carries the mass under another prior was gone when that
        prior was asked).
    refresh : int
        Readings between choices of the reference hypothesis whose radius of
        curvature scales the slope-error term (each choice evaluates the likelihood).
    jaw : StraightJaw
        The jaw, for where it can touch (:class:`localizer.Reach`).
    jaw_margin : float, mm
        How far a measured place on the jaw may be off when checking it against the reach.
    defect_window : float, mm
        The rolled arc of a stretch of readings the belief must not rest on alone, and over which
        :meth:`fit_test` judges whether the readings still fit the part (0: trust every reading, test
        nothing). docs/filter.md, "A part that is not its model".
    sd_jaw : float, mm
        Standard deviation of the B-spline coefficients of the calibration's error along the jaw
        (a smooth function of the contact's place on the jaw, the same all run long; 0: none).
        Measured on the simulated rig: about 0.45 of one reading's standard deviation.
    jaw_spacing : float, mm
        Knot spacing of that basis along the jaw.
    sd_drift : float, mm per reading
        Standard deviation of the sensor's drift rate, as the contact's place read on the jaw
        moves per reading, the same all run long (measured on the simulated rig: 5e-5 mm per
        reading at the ``paper`` preset).
    temper : float
        Power in (0, 1] on the readings' likelihood: below 1 the evidence counts for less than
        the noise model says (a guard against errors the model leaves out).
    sd_turn : float, rad
        Standard deviation of one reading of the net rotation (default: the arm encoder's
        0.03° step, uniform: 0.03°/√12). It moves the contact by ρ·e, which on a flat stretch
        (ρ of hundreds of mm) is more than the reading's own error.
    slope_envelope : sequence of float
        Other factors (> 0) on ``sd_slope``: the mass :meth:`belief` states is the least, over the
        slope prior and these, of the probability within ``radius`` of the most probable present
        contact (a lower probability over a set of priors; docs/filter.md, "Trust"). ``()``: the
        slope prior alone.
    lookalike_slope : float
        A factor on ``sd_slope`` under which a sure mass is also at most the probability that the start's
        nominal present contact is within :data:`LOOKALIKE_RADIUS` of the most probable one's: a look-alike
        place must be ruled out under a part off its model by a form tolerance, not only by machining
        (default :data:`localizer.LOOKALIKE_SLOPE`; 0: no such check). docs/filter.md, "A part that is not its model".
    corner_ends : bool
        Also state at most the probability under a prior that lays the jaw on a convex corner only at the
        ends of its jump (on one of the two pieces beside it), not at any angle within it (docs/filter.md,
        "A jaw laid on a corner"). No effect on a part without convex corners.
    stretch_weight : float
        The prior probability, in [0, 1], that a short stretch of the readings comes from a defect the
        model does not have: the stated mass is then ``(1 - q)·m + q·min(m, s)``, with ``m`` the mass the
        checks above leave and ``s`` the least mass without any one stretch of ``defect_window``
        (:meth:`stretch_mass`). 1: the least of the two (a stretch check that leaves nothing vetoes);
        default :data:`localizer.STRETCH_WEIGHT` (docs/filter.md, "A stretch check that weighs").
    noise_scales : sequence of float
        Common factors on ``sd_position``, ``sd_scale``, ``sd_slope`` and ``sd_jaw`` that the filter weighs
        with equal prior probability (the real noise is rarely what the settings say; docs/filter.md,
        "Noise it was not told"); ``(1.0,)`` trusts the settings.

    Examples
    --------
    >>> import numpy as np
    >>> from localizer import part_from_points
    >>> a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    >>> circle = part_from_points(np.c_[20 * np.cos(a), 20 * np.sin(a)])
    >>> f = ContactFilter(circle, sd_position=0.05)
    >>> for k in range(1, 11):   # ten 0.2° steps: 0.0698 mm of arc each on a 20 mm circle
    ...     f.update(k * 20 * np.radians(0.2), k * np.radians(0.2))
    >>> f.belief().informative   # every start fits equally well
    False
    """

    def update(self, arc: float, turn: float, jaw: float | None = None) -> None:
        """Take one reading.

        Parameters
        ----------
        arc : float, mm
            Cumulative *signed* arc the contact has travelled since the first reading
            (counter-clockwise positive): the sum of the steps' arcs, each signed by
            its rotation's direction.
        turn : float, rad
            Net jaw rotation since the first reading (counter-clockwise positive).
        jaw : float, mm, optional
            The contact's measured place on the jaw: checked against where the jaw can touch
            (:meth:`touch`).
        """
        if not (math.isfinite(arc) and math.isfinite(turn)):
            raise QueryError(f"arc={arc!r} mm and turn={turn!r} rad must be finite")
        # only the hypotheses still in the running are moved and summed (the pruned ones are
        # never evaluated again)
        idx = self._live_idx
        # the contact's last place on the jaw says where a jaw laid flush on a face presses it
        # (on a part with faces only: elsewhere the look-up would find none, once per reading)
        flush = self.tracks.has_faces and math.isfinite(self.jaw_position)
        current, node, ok = self.tracks.step(
            idx,
            turn,
            turn_margin=TURN_MARGIN,
            jaw=self.jaw_position if flush else None,
            at=self.current[idx] if flush else None,
            hint=self._hints,
        )
        if not ok.all():
            out = idx[~ok]
            self.feasible[out] = False
            self._live[out] = False
            self._live_idx = np.flatnonzero(self._live)
        p = np.where(ok, current - self.grid[idx], 0.0)
        self.current[idx] = np.where(ok, current, self.current[idx])
        self.node[idx] = np.where(ok, node, self.node[idx])
        z = float(arc)
        self._add_row(z, p, idx, jaw, float(turn))
        if any(lo <= z <= hi for lo, hi in self._zones):
            self._take_out(len(self._readings) - 1)
        self.steps += 1
        self.turn, self.arc = float(turn), z
        if jaw is not None:
            self._replaying += 1
            try:
                self.touch(jaw)
            finally:
                self._replaying -= 1
        if self.steps % self.refresh == 0:
            self._ref = int(np.argmax(self.log_likelihood()))
            self._slope_priors()
        self._log("update", arc, turn, jaw)  # once it has been taken: a call that failed is not replayed

    def touch(self, jaw: float) -> None:
        """The contact is now at place ``jaw`` (mm from the jaw's centre) on the jaw.

        A hypothesis whose present contact the jaw cannot touch there (``jaw_margin`` given)
        is made :data:`CONTRADICTION` times less likely: the first contact's place rules out
        the starts the jaw could not have been laid on, each reading those it could not have
        rolled to.
        """
        if not math.isfinite(jaw):
            raise QueryError(f"jaw={jaw!r} mm must be finite")
        self.jaw_position = float(jaw)
        if self._rows == 1 and self.sd_jaw > 0:
            # the first reading (z = 0, p = 0) is where the jaw was laid: it carries the calibration's
            # error at that place too (only UᵀU changes, z and p being 0)
            old_cols, old_vals = self._last_row
            cols, vals = self._basis(0.0, jaw)
            wt2 = self._row_weight**2
            self._uu[np.ix_(old_cols, old_cols)] -= wt2 * np.outer(old_vals, old_vals)
            self._uu[np.ix_(cols, cols)] += wt2 * np.outer(vals, vals)
            self._touched[cols] = True
            self._last_row = (cols, vals)
            self._readings[0] = self._readings[0]._replace(cols=cols, vals=vals * self._row_weight)
            self._version += 1
        idx = self._live_idx
        ok = self.tracks.touches(self.current[idx], float(jaw), self.jaw_margin, node=self.node[idx])
        if not ok.all():
            self._penalty[idx[~ok]] += math.log(CONTRADICTION)
            self._version += 1
        self._log("touch", jaw)

    def bridged(self, turn: float, jaw: float | None = None, jump: float = BRIDGE_JUMP) -> float:
        """The jaw, turned to net rotation ``turn`` (rad), touched the part somewhere else (a bridge).

        The rig calls a step a bridge when the contact moves more than ``jump`` mm along the jaw
        in it (or cannot be read). ``jaw`` (mm) is the contact's place on the jaw at the last
        reading (default: the last one given). A hypothesis under which that turn, and
        :data:`TURN_MARGIN` more, keep the contact on its convex stretch, the turn moving it by
        less than half of ``jump``, with the jaw clear by ``jaw_margin`` there, did not expect it and
        is made :data:`BRIDGE_MISS` times less likely; the others predicted it (a concavity, or a
        flat stretch where one step moves the contact far) or cannot tell. No reading is added:
        call :meth:`regrasp` with the next one.

        Returns
        -------
        float
            The probability, before this evidence, that the part's model predicted the bridge: near 0
            where no place the belief holds has a concavity there (a burr or debris the jaw met, not the
            part the model describes: :meth:`bridge_predicted` asks it again for any start later).
        """
        if not (math.isfinite(turn) and math.isfinite(jump) and jump > 0):
            raise QueryError(f"turn={turn!r} rad and jump={jump!r} mm must be finite, jump positive")
        d0 = self.jaw_position if jaw is None else float(jaw)
        self._log("bridged", turn, jaw, jump)
        if not math.isfinite(d0) or self.ruled_out:
            return 1.0
        idx = self._live_idx
        w = self.posterior()[idx]
        clear = self._surely_clear(idx, self.turn, float(turn), d0, float(jump), at=self.current[idx])
        predicted = float(w[~clear].sum())
        if predicted < UNEXPLAINED:
            self._bridges.append((self.turn, float(turn), d0, float(jump)))
        if clear.any():
            self._penalty[idx[clear]] += math.log(BRIDGE_MISS)
            self._version += 1
        return predicted

    def unexplained_bridges(self, start: int) -> list[tuple[float, float, float, float]]:
        """The bridges reported so far (:meth:`bridged`) that the belief gave less than :data:`UNEXPLAINED`
        when they came and that the start ``start`` (a grid index) does not predict either, each as (net
        rotation before it, rad; the turn it came at, rad; the contact's place on the jaw, mm; the jump,
        mm): none where the model explains every jump the rig saw."""
        idx = np.array([int(start)], dtype=np.int64)
        return [b for b in self._bridges if bool(self._surely_clear(idx, *b)[0])]

    def regrasp(self, arc: float, turn: float, jaw: float | None = None) -> None:
        """The jaw was lifted and put back (e.g. slid along itself at the end of its span).

        The contact is where the net rotation ``turn`` (rad) puts it, but the next
        reading starts a new segment with its own unknown offset (the arc across the
        lift is not measured). ``arc`` (mm) is the cumulative arc to continue from:
        pass the last reading's, since the contact has not moved along the part. The
        new offset absorbs any error in it; it also places the reading on the slope
        error's basis, so it should be right to a few mm. ``jaw`` (mm) is the contact's
        new place on the jaw, as in :meth:`update`.
        """
        if self._segment + 1 >= self._segments:
            raise QueryError(f"more than {self._segments - 1} regrasps in one localization")
        self._segment += 1
        self._replaying += 1
        try:
            self.update(arc, turn, jaw)
        finally:
            self._replaying -= 1
        self._log("regrasp", arc, turn, jaw)

    def _rebuild(self, out: set[int]) -> None:
        """Take every reading in ``out`` (indices, as :meth:`set_quarantine`) out of the likelihood *from the
        start*: the filter is reset and its calls made again, each such reading taken out as it comes.

        Taking readings out of the sums afterwards (:meth:`set_quarantine`) reaches only the starts still
        live: a burr's readings may have pruned the true start long before the fit test found them (40
        nats is a few readings 5 sigma off), and nothing then brings it back. The calls' own records (the
        bridges and whether they were explained when they came, the fit tests' state) are kept."""
        calls, misfits, bridges, fit_next = self._calls, self._misfits, self._bridges, self._fit_next
        zones = self._zones
        self.reset()
        self._zones = zones
        self._replaying += 1
        try:
            for name, args in calls:
                getattr(self, name)(*args)
                j = len(self._readings) - 1
                if name in ("update", "regrasp") and j in out and j not in self._out:
                    self._take_out(j)
        finally:
            self._replaying -= 1
        self._calls, self._misfits, self._bridges, self._fit_next = calls, misfits, bridges, fit_next

    def belief(self, radius: float | None = None) -> Belief:
        """The belief over the present contact (see :class:`Belief`), its mass taken within ``radius`` mm
        (default: the filter's ``radius``); the mass is 0 where the readings fit the most probable start only as
        noise more than :data:`~localizer.NOISE_FIT_LIMIT` times what the filter was told."""
        radius = self.radius if radius is None else float(radius)
        part = self.part
        if not self._live.any():  # every start ruled out: nothing on the part fits the readings
            return Belief(
                map_arc=self._last_map,
                mass=0.0,
                radius=radius,
                modes=(),
                ambiguous=False,
                informative=True,
                steps=self.steps,
                consistent=False,
                mismatch=self._misfits[-1].arcs if self._misfits else self._last_span,
            )
        w = self.posterior()
        mean, sd = self.shift()
        present = part.wrap_arc(self.current + mean)
        i = int(np.argmax(w))
        map_arc = float(present[i])
        mass = self._mass_near(w, present, sd, map_arc, radius)
        # the same event under the envelope's other slope priors: the stated mass is the least
        for factor in self.slope_envelope:
            w_f = self._posterior(factor)
            mean_f, sd_f = self._shift(factor)
            mass = min(mass, self._mass_near(w_f, part.wrap_arc(self.current + mean_f), sd_f, map_arc, radius))
        if self.tracks.has_faces:
            # ... and with the contact just past a face counted anywhere on that face's end (docs/filter.md)
            mass = min(mass, self._mass_past_faces(w, present, sd, map_arc, radius))
        if self.corner_ends and self.tracks.pivot.any():
            # ... and under a prior that lays the jaw on a corner only at its jump's ends: a pure pivot tells
            # only that the corner's jump is at least the pivot, so the uniform prior over the jump alone
            # would decide between two such corners (docs/filter.md, "A jaw laid on a corner")
            w_e = np.where(self._inside_corner, 0.0, w)  # per start: a start's table node is its index
            total = float(w_e.sum())
            if total > 0:
                mass = min(mass, self._mass_near(w_e / total, present, sd, map_arc, radius))
        if self.lookalike_slope > 0 and mass >= self.confidence:
            # ... and no look-alike place under a part a form tolerance off its model: which place, so the
            # starts' nominal present contacts (the slope term's offset there is the envelope's question).
            # Asked only where it would decide: the starts it weighs are those live under the envelope
            nominal = part.wrap_arc(self.current)
            w_f = self._posterior(self.lookalike_slope)
            zero = np.zeros_like(nominal)
            mass = min(mass, self._mass_near(w_f, nominal, zero, float(nominal[i]), LOOKALIKE_RADIUS))
        if self.slope_envelope:
            self._prune_under_every_prior()
        modes = self._modes(w, present, radius)
        # ... and, with the weight ``stretch_weight``, without any one short stretch of the readings (a burr,
        # a dent, debris): asked only where it could decide, at the confidence, once per state of the readings
        if mass >= self.confidence and self.defect_window > 0:
            key = (self._version, radius, map_arc)
            if self._stretch_cache[0] != key:
                self._stretch_cache = (key, self.stretch_mass(map_arc, radius)[0])
            q = self.stretch_weight
            mass = (1.0 - q) * mass + q * min(mass, self._stretch_cache[1])
        # do the readings still fit the part? Tested every FIT_EVERY readings and before a sure stop,
        # under the most probable starts: a stretch that fits none of them is taken out of the
        # likelihood (quarantined: it costs its readings, not the answer) and the belief asked again
        if len(self._misfits) < MAX_QUARANTINE and (
            (mass >= self.confidence and self._fit_version != self._version) or self.steps >= self._fit_next
        ):
            self._fit_next = self.steps + FIT_EVERY
            self._fit_version = self._version
            # the most probable starts, and each strong mode's best: all of them must misfit
            strong = [m for m in modes if m.mass >= self.mode_floor][:3]
            top = most_probable(w, FIT_STARTS)
            reps = [i] + [int(self.tracks.node_at(m.start_arc)) for m in strong[1:]]
            reps += [int(h) for h in top if w[h] > 0 and int(h) not in reps]
            found = self.fit_test(reps)
            if found is not None:
                # which stretch to take out: the one whose absence lets some start fit best, not
                # necessarily the one the most probable start misfits (a wrong start that the stretch
                # made probable would otherwise keep it and drop the rest)
                rows = self._best_stretch()
                if any(m.travel == found.travel for m in self._misfits):
                    # ... unless the test finds the same window again (laid out from the same least rolled arc
                    # of the readings it judges): what was taken out for it was not it
                    rows = found.rows
                self._misfits.append(found._replace(rows=rows) if rows else found)
                taken = list(rows or found.rows)
                # the zone: the stretch's readings, and at least one defect window around their middle (on a
                # burr's crest the contact creeps on a fraction of a millimetre per 25 readings)
                arcs = [self._readings[j].arc for j in taken]
                mid, half = 0.5 * (min(arcs) + max(arcs)), 0.5 * self.defect_window
                self._zones.append((min(min(arcs), mid - half), max(max(arcs), mid + half)))
                self._rebuild(self._out | set(taken))
                return self.belief(radius)
        self._last_map = map_arc
        self._last_span = (map_arc, map_arc)
        prior = self.feasible.astype(float) if self.steps == 0 else self.tracks.convex.astype(float)
        prior /= prior.sum()
        informative, ambiguous = belief_flags(w, prior, modes, self.mode_floor, self.confidence)
        # readings that fit the most probable start only as noise many times the rig's say nothing of where the
        # contact is: no probability is stated on them (the rolling goes on; the fit test may yet find the stretch)
        if mass > 0 and self.steps >= FIT_MIN_READINGS and self.noise_scale() > NOISE_FIT_LIMIT:
            mass = 0.0
        return Belief(
            map_arc=map_arc,
            mass=mass,
            radius=radius,
            modes=tuple(modes),
            ambiguous=ambiguous,
            informative=informative,
            steps=self.steps,
            mismatch=self._where(self._in_travel(self._misfits[0].travel), i) if self._misfits else None,
            mismatch_mm=self._misfits[0].rms_mm if self._misfits else math.nan,
        )

    @property
    def ruled_out(self) -> bool:
        """Every start is ruled out: nothing on the part fits the readings (:meth:`belief` then says so)."""
        return not bool(self._live.any())

    @property
    def misfits(self) -> tuple[Misfit, ...]:
        """The stretches of readings found not to fit the part (:meth:`fit_test`, asked by :meth:`belief`),
        in the order found; the readings of each are quarantined (out of the likelihood)."""
        return tuple(self._misfits)
