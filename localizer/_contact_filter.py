"""Sequential localization while rolling: the exact grid filter over the start of the rolling.

The jaw rolls on a convex stretch of the part. With the contact at arc
position σ₀ when the rolling starts, a net jaw rotation Ω puts it at the σ
where the tangent angle θ(σ) = θ(σ₀) + Ω (counter-clockwise rotation, contact
moving counter-clockwise), so the whole path is fixed by σ₀ and the
rotations. What the wrist measures along the way is the contact's travel
on the jaw, turned into arc length step by step
(:func:`localizer.arc_from_jaw_positions`).

**ContactFilter** (exact on a grid). The hypotheses are the starts σ₀ on a grid
of ``spacing`` mm over the whole boundary. After k steps, the measured
cumulative signed arcs z_0 = 0, z_1, …, z_k and the predicted ones
p_j(σ₀) = σ(θ(σ₀) + Ω_j) − σ₀ are related by

    z_j = c_s + b·p_j(σ₀) + δ(z_j) + g(d_j) + r·j + e_j,
    e_j ~ N(0, sd_position² + (ρ̂_j·sd_turn)²) independent,

- c_s, one per contact segment (a regrasp or a bridge starts a new one), absorbs
  the first reading's error (flat prior);
- b is the calibration's scale, b ~ N(1, sd_scale²);
- δ is the machining error's effect: a slope error η of the real boundary against
  its model (rad) moves the contact for a given jaw angle by δ = ρ·η, ρ the radius
  of curvature there. δ is a smooth function along the path, cubic B-splines in z
  with knots every ``shape_spacing`` mm, each coefficient ~ N(0, (ρ̂·sd_slope)²)
  with ρ̂ the largest model radius over its support along the path of a reference
  hypothesis, the most probable one (re-chosen every ``refresh`` readings; the
  part's median radius before the first), the same for every hypothesis. ρ̂ must
  not be measured from the readings themselves (arc over rotation over the last
  few steps): that puts the reading noise into the model and the term fits it. Nor
  may the basis' *values* be scaled by ρ̂: when the reference changes, ρ̂ jumps, the term's constant part then
  looks measured, and on a flat stretch the belief said 97% at 0.35 mm off. Only
  the coefficients' prior changes, which the running sums do not depend on. δ
  repeats when the jaw rolls over the same stretch again, so more rolling does not
  average it away; its value at the last reading is how far the real present
  contact is from where the model puts it (:meth:`ContactFilter.shift`), and the
  belief includes it and its spread;
- g is the calibration's error along the jaw: the contact's place on the jaw d_j is
  read through a spline of 11 taps, whose error is a smooth function of d, the same
  all run long (measured on the simulated rig: about 0.45 of one reading's standard
  deviation, with a correlation length of about 10 mm). Rolling back and forth over
  one corner reads the same places again, so without g the same error counted as
  fresh evidence each time (the belief said 99% for the wrong one of two look-alike
  corners). Cubic B-splines in d every ``jaw_spacing`` mm, coefficients
  ~ N(0, sd_jaw²);
- r·j is the sensor's drift (one way, paper §III-B), a rate r ~ N(0, sd_drift²) per
  reading. Rolling back and forth over one corner for minutes, it made a wrong corner
  12 mm away look better by 6 nats (measured: 0.03 mm per minute at the ``paper``
  preset);
- e_j, the reading's own error, with the rotation reading's error moving the
  contact by ρ·e_Ω (the arm encoder's 0.03° steps: on a flat stretch of ρ = 300 mm
  that is 0.05 mm, more than the reading's own error).

c, b, δ, g and r are integrated out in closed form (Woodbury): each hypothesis keeps
running sums (pᵀp, pᵀz and the basis projections Uᵀp, of which a reading touches
ten), so one step costs a few vector operations on the grid, and the belief a
small dense solve.

*Noise it was not told.* Every standard deviation above is the setting times one
common factor λ, unknown, with a log-uniform prior over :data:`NOISE_SCALES` (a
quarter to sixteen times). Scaling every standard deviation by λ scales the
quadratic form by 1/λ² and the determinant by λ^(2k), k the readings not absorbed
by a segment's offset, and leaves the rest unchanged, so each hypothesis' marginal
likelihood over λ costs a few vector operations per grid value. The readings thus
set the noise level themselves: told 0.035 mm and read at 0.14, the belief widens
instead of stopping sure and wrong.

*Where the jaw reaches* (:class:`localizer.Reach`). A start on a concave stretch,
or a roll that would cross an inflection, is ruled out (a straight jaw bridges
there, which the rolling procedure undoes and reports). Each reading's place on
the jaw (:meth:`ContactFilter.touch`) must be one at which the jaw can touch the
hypothesis' present contact, within ``jaw_margin``: else the hypothesis is made
:data:`CONTRADICTION` times less likely. A reported bridge makes the hypotheses
under which the jaw surely stayed clear :data:`BRIDGE_MISS` times less likely
(:meth:`ContactFilter.bridged`). Both are soft: a misread place or a refused press
for another reason must not rule out the truth.

*Trust.* The stop rule looks at the belief every few steps and stops at the first
crossing of the confidence. Even for a posterior that is exactly right, the odds
of a wrong place against the true one are a martingale, and the chance that they
ever reach 19 (95%) is up to 1/19: stopping at the first crossing of 0.95 is
wrong up to 5% of the time, and the model leaves out some errors (the encoder's
three-step cycle, the ADC's pattern). The readings' likelihood is therefore
raised to the power :data:`TEMPER` (½): a stop at 95% then needs the odds the
model alone would put at 19² = 361. Measured on the tuning family (bench/parts/
tuning, noise ×0.7, ×1.4, ×2.8): 3 of 119 confident stops wrong at power 1, 0 of
118 at ½, for 7° more rolling on average. The spread of the slope term at the present
contact is widened to match (its variance over ½): without it, at four times the
``paper`` noise 9 of 91 stops were 0.31–0.48 mm off at a stated 95–97%.

*A set of slope priors.* The slope term must be flexible enough for the machining error at the
present contact (else near misses at a stated 95%), yet, being shared by every start, it lets a
look-alike place 160 mm away explain its difference away: on a glyph at four times the ``paper``
noise the look-alike led by 11 nats with the slope prior and trailed by 34 without the term.
Averaging over the prior's scale does not help (the readings prefer the wider one for the truth and
the look-alike alike). So the stated mass is a *lower* probability over a set of priors: the
probability within the radius of the most probable contact under the slope prior, and under the
same prior times each factor of :data:`SLOPE_ENVELOPE` (¼: stiffer, against look-alikes; 2:
looser, against near misses at the estimate's own spread), whichever is least. The running sums
do not depend on the prior, so each factor costs one more closed-form solve per belief. Chosen on
the tuning family (100 trials per level, ×0.7/×1.4/×2.8/×5.6; confident and wrong): the slope prior
alone 0/0/0/11, with {¼} 0/0/0/5, with {¼, 2} 0/0/0/1, with {¼, 4} 0/0/0/0 but sure in only 21 of
100 trials at ×2.8.

*A jaw laid on a corner.* A convex corner is a range of starts, one per jaw angle within its jump, each
as likely a priori as a start on a piece (the tracks spread a corner over ``PIVOT_SPREAD`` mm per
radian). A pure pivot, the jaw turning on the corner with no contact travel, tells only that the
corner's jump is at least the pivot; between two corners that both allow it, the uniform prior over
the jaw's angle then decides, in proportion to how many of each corner's angles allow the pivot: a
plate's 81.7° corner outweighed the true 64.3° one 60 to 1 after a 64° pivot, where the jaw had been
laid on the face before the corner (sure and wrong, 94 mm off). A jaw put on a part from a face lies at
a corner's ends more often than inside it, so the stated mass is also at most the probability under a
prior that lays the jaw on a corner only at the ends of its jump (``corner_ends``): under it such a
pivot leaves the corners equally likely.

*A face just crossed.* Turned past a face's angle, the model's contact is on the piece after it, where the
tangent has turned that much; but the machined face is locally tilted by several of its slope errors, and
until the jaw has turned past that the real contact may still be on the face, anywhere short of its end
(a plate, 0.18° past a 46 mm face: the model put the contact 0.01 mm into the next fillet, the rig's jaw
rested on the face 0.35 mm before its end, stated 1.00). Within :data:`FACE_SLOPES` slope errors of a
face's angle, a start's present contact counts as anywhere from the face's far end to the model's contact.

The belief over the *present* contact is the push-forward of the posterior over
σ₀ (with the slope term's offset at the last reading, except on a pivot: there the real contact
is the corner, which machining moves along its normal only). :meth:`ContactFilter.belief`
reports its maximum, the probability within the success radius of it, the separate modes, and
whether the data said anything at all (on a circle every start predicts the same readings).

*A part that is not its model* (docs/robustness.md). A burr, a dent, debris, a part made
large or to another revision: where the jaw rolls over such a thing the readings follow a shape the
model does not have, and a burr's crest, a tight convex bend, reads like a fillet of the model
somewhere else. Three things keep the belief honest about it:

- *No belief rests on one short stretch.* Every reading is kept as the sums took it, so that any
  stretch can be taken out exactly (the marginalisation without its sums). The stated mass is the
  least, over every stretch of :data:`DEFECT_WINDOW` mm of rolled arc, of the mass without that
  stretch (:meth:`ContactFilter.stretch_mass`, asked only where the belief would otherwise stop);
  readings that span no more than one stretch are not enough to be sure of anything. Rolling on a
  burr's crest, the jaw is sure of nothing until it has read the part beyond it.
- *A fit test.* Every :data:`FIT_EVERY` readings, and before a sure stop, each stretch of
  :data:`FIT_WIDTH` windows is judged under the most probable starts: its misfit per reading, against
  what the error model expects of each reading under that start (the rotation reading's ρ·e is the
  start's own), over the rest's is an F ratio, scale-free, so that noise of any level fits. A stretch
  at least :data:`FIT_RATIO` times as far off as the rest and as the told noise, at a Bonferroni-
  corrected :data:`~localizer.FIT_ALPHA`, under every one of those starts, is a misfit
  (:meth:`ContactFilter.fit_test`).
- *Quarantine.* Such a stretch costs its readings, not the answer: the stretch whose absence lets some
  start fit best (not necessarily the one the most probable start misfits: a wrong start that the
  stretch made probable would keep it) is taken out of the likelihood, up to :data:`MAX_QUARANTINE` of
  them, and the belief is asked again. It is taken out as a *zone* of rolled arc, at least one window
  wide: a reading taken there later is taken out as it comes (on a burr's crest the jaw lingers for
  tens of degrees while the contact creeps a fraction of a millimetre). And it is taken out *from the
  start*: the filter is reset and its logged calls made again without the zone's readings
  (:meth:`_rebuild`), since the stretch's few readings 5σ off may have pruned the true start long before
  the test found them, and taking readings out of the sums afterwards (:meth:`set_quarantine`) reaches
  only the starts still live. :attr:`Belief.mismatch` then says where
  on the model, under the most probable start, the first one lies, and ``mismatch_mm`` how far off the
  readings were there; a belief with a mismatch is never sure (:meth:`Belief.sure`).

- *A look-alike under a form tolerance.* The slope prior (``sd_slope``, 1 mrad) is the machining's; a
  part a few hundredths of a millimetre off its drawing where that error changes over a few millimetres
  (a part made from a re-fitted curve, a scan: the model resampled moves 22 µm and tilts 11 mrad) moves
  the contact by ρ·η, 0.3 mm at ρ = 30 mm, and the difference that told a star's arm from its look-alike
  then lay in that error: sure at 0.951, 386 mm off. Which *place* it is must therefore hold under the
  slope prior :data:`LOOKALIKE_SLOPE` times wider too: where the belief would be sure, the stated mass
  is at most the probability, under that prior, that the start's nominal present contact is within
  :data:`LOOKALIKE_RADIUS` of the most probable one's (nominal: the wide prior's offset at the present
  contact is not the question here, and would make the answer "nowhere" on a flat stretch). Asked at
  every belief and pruned under, the wide prior kept ten thousand starts live and tripled the cost of a
  rolling; asked where it decides, it weighs the starts the envelope keeps. Weighing the slope prior's scale by the
  readings' evidence instead (Occam's factor included) was tried on the tuning family and dropped: the
  simulated machining itself is up to twice the told prior, so the readings chose 2 to 16 times on
  clean parts and half the sure stops were lost.

A bridge that no probable start predicted (:meth:`bridged` returns the probability it had) is kept,
so that the rolling can ask whether the final place explains it (:meth:`unexplained_bridges`). And a
part uniformly a little larger or smaller than its model scales every measured arc: the scale term
``sd_scale`` carries it with the calibration's (:data:`SCALE_SD`: 0.3% and 1% in quadrature, a part
2% off its drawing at two standard deviations).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from typing import Any, NamedTuple

import numpy as np
from scipy.special import ndtr
from scipy.stats import f as f_dist

from ._belief import Belief, Mode, belief_flags, find_modes
from ._boundary import Boundary
from ._defaults import CALIBRATION_SCALE_SD, CONFIDENCE, FIT_ALPHA, PART_SCALE_SD, SUCCESS_RADIUS
from ._errors import QueryError
from ._filter_kernels import add_row, weigh_scales
from ._limits import check_grid
from ._pieces import Line
from ._reach import DEFAULT_JAW, StraightJaw
from ._stretches import (
    DEFECT_WINDOW,
    FIT_EVERY,
    FIT_MIN_READINGS,
    FIT_RATIO,
    FIT_STARTS,
    FIT_WIDTH,
    JUMP_READING,
    MAX_QUARANTINE,
    UNEXPLAINED,
    Misfit,
    stretch_windows,
)
from ._tracks import grid_size, tracks_for
from ._types import ArrayLike, BoolArray, FloatArray, IntArray

__all__ = [
    "ContactFilter",
    "NOISE_SCALES",
    "TEMPER",
    "SLOPE_ENVELOPE",
    "CONTRADICTION",
    "BRIDGE_MISS",
    "ENCODER_SD",
    "TURN_MARGIN",
    "SCALE_SD",
    "LOOKALIKE_SLOPE",
    "LOOKALIKE_RADIUS",
]

#: Factors on the filter's noise settings it weighs when it is not sure of them (module notes): a
#: log-uniform prior in steps of 2^(1/4) from a quarter to sixteen times what it was told. The
#: steps are fine because with hundreds of readings the scale's posterior is sharp (a few per cent):
#: a coarse grid would round it, and an underestimated scale overstates the evidence.
NOISE_SCALES = tuple(float(2.0 ** (k / 4)) for k in range(-8, 17))
#: The power on the readings' likelihood: the evidence counts half (module notes, "Trust").
TEMPER = 0.5
#: Other factors on ``sd_slope`` under which the stated mass must hold as well (module notes, "Trust"):
#: the belief's mass is the least over the slope priors (1, then these).
SLOPE_ENVELOPE = (0.25, 2.0)
#: Probability that one reading puts the contact where the jaw cannot touch under the true start
#: (a jaw position misread by more than ``jaw_margin``, a model error in the part's reach).
CONTRADICTION = 1e-3
#: Probability that the rig reports a bridge where the jaw surely clears (a press refused for
#: another reason).
BRIDGE_MISS = 0.05
#: Standard deviation of one reading of the arm's rotation, rad: its encoder's 0.03° step (the
#: Adept Cobra 600, paper §IV), a uniform error.
ENCODER_SD = math.radians(0.03) / math.sqrt(12.0)
#: The largest radius of curvature, mm, the error model takes: the slope error's and the rotation
#: reading's effects on the contact grow with ρ, and on a straight stroke of a glyph or a flat side
#: (ρ of metres) the readings cannot place the contact along it, which the model must say.
RHO_MAX = 5000.0
#: How many of the machined slope's standard deviations (``sd_slope``) past a face's angle the jaw must have
#: turned before its contact is taken to have left the face: a face machined wavy by microns over
#: millimetres is locally tilted by several (module notes, "A face just crossed").
FACE_SLOPES = 5.0
#: The largest radius, mm, the slope term's prior takes: beyond it the offset's prior is so wide
#: (metres times mrad) that it makes the marginalisation ill-conditioned, and it is already wide
#: enough to leave the contact's place on such a stretch to the other readings.
SLOPE_RHO_MAX = 1000.0
#: The factor on ``sd_slope`` under which a look-alike place must be ruled out too (module notes, "A part
#: that is not its model"): a part a few hundredths of a millimetre off its drawing, where that error
#: changes over a few millimetres, has slopes several mrad off (the model resampled: 22 µm, 11 mrad),
#: which at ρ = 30 mm moves the contact 0.3 mm along a roll: more than what told a star's arm from its
#: look-alike 386 mm away, at a stated 0.951.
LOOKALIKE_SLOPE = 8.0
#: How near, mm, a start's nominal present contact must be to the most probable one to count as the same
#: place in the look-alike check: farther is another feature of the part; nearer, the envelope's
#: radius judges the spread.
LOOKALIKE_RADIUS = 3.0
#: How far, rad, a rotation may run past the model's end of a convex stretch and keep the contact
#: at that end: the machined part's slope differs from the model's by 0.6 mrad RMS at the `paper`
#: preset, peaks of 10 mrad at five times that.
TURN_MARGIN = 0.02
#: The prior standard deviation of the scale of every measured arc against the model's: the
#: calibration's and the part's own (module notes, "A part that is not its model").
SCALE_SD = math.hypot(CALIBRATION_SCALE_SD, PART_SCALE_SD)

#: How many stretches of readings are left out at once (one batched solve; its arrays are this many
#: times the filter's own, so early in a rolling, with every start live, a few tens of MB at most).
STRETCH_BATCH = 8


def _quad(s: dict[str, Any], t2: float) -> FloatArray:
    """Each hypothesis' quadratic form of a :meth:`ContactFilter._solve` (the readings' misfit in units of
    the told reading variance, every nuisance and the calibration's scale, of prior variance ``t2``,
    weighed out)."""
    qpp, qpz = s["qpp"], s["qpz"]
    qpr = qpz - qpp
    out: FloatArray = s["qzz"] - 2 * qpz + qpp - t2 * qpr**2 / (1 + t2 * qpp)
    return out


class _Sums(NamedTuple):
    """Sums of some stretches of readings, one per leading index: UᵀU, Uᵀz, zᵀz, and Uᵀp, pᵀp, zᵀp over some
    hypotheses; how many readings. The basis terms over the columns ``cols`` only (those any reading has
    touched)."""

    cols: IntArray
    uu: FloatArray
    uz: FloatArray
    szz: FloatArray
    up: FloatArray
    spp: FloatArray
    szp: FloatArray
    readings: FloatArray


class _Stack(NamedTuple):
    """Some readings, weighted: their basis rows over the columns ``cols`` (k, c), values (k,) and predictions
    at some hypotheses (k, n)."""

    cols: IntArray
    a: FloatArray
    z: FloatArray
    p: FloatArray


def _sums(stack: _Stack, stretches: Sequence[IntArray]) -> _Sums:
    """The sums of each stretch of readings (their positions in ``stack``), along a leading axis."""
    mask = np.zeros((len(stretches), stack.z.size))
    for n, at in enumerate(stretches):
        mask[n, at] = 1.0
    masked = np.swapaxes(mask[:, :, None] * stack.a, 1, 2)  # (stretches, c, k)
    return _Sums(
        cols=stack.cols,
        uu=masked @ stack.a,
        uz=masked @ stack.z,
        szz=mask @ stack.z**2,
        up=masked @ stack.p,
        spp=mask @ stack.p**2,
        szp=mask @ (stack.z[:, None] * stack.p),
        readings=mask.sum(axis=1),
    )


class _Reading(NamedTuple):
    """One reading as the sums took it: basis columns and weighted values, the weighted z, the hypotheses
    live then and their weighted predictions, the reading's own arc (mm) and turn (rad), its segment."""

    cols: IntArray
    vals: FloatArray
    z: float
    live: IntArray
    p: FloatArray
    arc: float
    turn: float
    segment: int
    weight: float
    radius: float  # the reference's radius of curvature then (mm; 0 on a face or a concave stretch)


def _bspline(x: float) -> tuple[IntArray, FloatArray]:
    """(indices, values) of the four uniform cubic B-splines that are nonzero at ``x`` (in knot steps)."""
    i = math.floor(x)
    u = x - i
    vals = np.array([(1 - u) ** 3, 3 * u**3 - 6 * u**2 + 4, -3 * u**3 + 3 * u**2 + 3 * u + 1, u**3]) / 6
    return i + np.arange(4), vals


class ContactFilter:
    """Exact Bayesian filter over the start of the rolling, on a grid (see the module notes).

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
        nothing). Module notes, "A part that is not its model".
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
        contact (a lower probability over a set of priors; module notes, "Trust"). ``()``: the
        slope prior alone.
    lookalike_slope : float
        A factor on ``sd_slope`` under which a sure mass is also at most the probability that the start's
        nominal present contact is within :data:`LOOKALIKE_RADIUS` of the most probable one's: a look-alike
        place must be ruled out under a part off its model by a form tolerance, not only by machining
        (default :data:`LOOKALIKE_SLOPE`; 0: no such check). Module notes, "A part that is not its model".
    corner_ends : bool
        Also state at most the probability under a prior that lays the jaw on a convex corner only at the
        ends of its jump (on one of the two pieces beside it), not at any angle within it (module notes,
        "A jaw laid on a corner"). No effect on a part without convex corners.
    noise_scales : sequence of float
        Common factors on ``sd_position``, ``sd_scale``, ``sd_slope`` and ``sd_jaw`` that the filter weighs
        with equal prior probability (the real noise is rarely what the settings say; module
        notes); ``(1.0,)`` trusts the settings.

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

    def __init__(
        self,
        part: Boundary,
        *,
        spacing: float = 0.02,
        sd_position: float = 0.035,
        sd_scale: float = SCALE_SD,
        sd_slope: float = 0.001,
        shape_spacing: float = 5.0,
        radius: float = SUCCESS_RADIUS,
        mode_floor: float = 0.05,
        confidence: float = CONFIDENCE,
        prune: float = 40.0,
        refresh: int = 5,
        jaw: StraightJaw = DEFAULT_JAW,
        jaw_margin: float = 2.0,
        noise_scales: ArrayLike = NOISE_SCALES,
        slope_envelope: ArrayLike = SLOPE_ENVELOPE,
        lookalike_slope: float = LOOKALIKE_SLOPE,
        corner_ends: bool = True,
        sd_jaw: float = 0.015,
        jaw_spacing: float = 5.0,
        sd_turn: float = ENCODER_SD,
        temper: float = TEMPER,
        sd_drift: float = 1e-4,
        defect_window: float = DEFECT_WINDOW,
    ) -> None:
        for name, value in (("spacing", spacing), ("sd_position", sd_position), ("radius", radius)):
            if not (math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} mm must be a positive number")
        for name, value in (
            ("sd_scale", sd_scale),
            ("sd_slope", sd_slope),
            ("sd_jaw", sd_jaw),
            ("sd_turn", sd_turn),
            ("sd_drift", sd_drift),
            ("lookalike_slope", lookalike_slope),
        ):
            if not (math.isfinite(value) and value >= 0):
                raise QueryError(f"{name}={value!r} must be ≥ 0")
        for name, value in (("shape_spacing", shape_spacing), ("jaw_spacing", jaw_spacing)):
            if not (math.isfinite(value) and value > 0):
                raise QueryError(f"{name}={value!r} mm must be positive")
        if not 0 < confidence < 1:
            raise QueryError(f"confidence={confidence!r} must be in (0, 1)")
        if isinstance(refresh, bool) or not isinstance(refresh, (int, np.integer)) or refresh < 1:
            raise QueryError(f"refresh={refresh!r} must be a whole number of readings ≥ 1")
        scales = np.asarray(noise_scales, dtype=float).ravel()
        if scales.size == 0 or not np.all(np.isfinite(scales) & (scales > 0)):
            raise QueryError(f"noise_scales={noise_scales!r} must be positive factors")
        envelope = np.asarray(slope_envelope, dtype=float).ravel()
        if not np.all(np.isfinite(envelope) & (envelope > 0)):
            raise QueryError(f"slope_envelope={slope_envelope!r} must be positive factors")
        if not (math.isfinite(temper) and 0 < temper <= 1):
            raise QueryError(f"temper={temper!r} must be in (0, 1]")
        if not (math.isfinite(jaw_margin) and jaw_margin >= 0):
            raise QueryError(f"jaw_margin={jaw_margin!r} mm must be ≥ 0")
        if not (math.isfinite(defect_window) and defect_window >= 0):
            raise QueryError(f"defect_window={defect_window!r} mm must be ≥ 0 (0: trust every stretch)")
        self.defect_window = float(defect_window)
        # the stretches the fit test judges: twice the envelope's (a burr's misfit and its edges)
        self._fit_width = FIT_WIDTH * self.defect_window
        self.part = part
        self.jaw = jaw
        self.jaw_margin = float(jaw_margin)
        self.temper = float(temper)
        self.noise_scales = tuple(float(v) for v in scales)
        self.slope_envelope = tuple(float(v) for v in envelope if v != 1.0) if sd_slope > 0 else ()
        self.lookalike_slope = float(lookalike_slope) if sd_slope > 0 else 0.0
        self.corner_ends = bool(corner_ends)
        self.jaw_spacing = float(jaw_spacing)
        # basis columns: 0 the constant, then B-splines B_k(z) for knots over z in [-P, P]
        self._k0 = int(math.ceil(part.perimeter / shape_spacing)) + 3
        self._segments = 48  # offsets: one per contact segment (see regrasp)
        self._jaw0 = self._segments + (2 * self._k0 + 4 if sd_slope > 0 else 0)
        # then the calibration error's B-splines over the jaw's span and the margin beyond it
        self._jaw_lo = -(jaw.half + self.jaw_margin) - self.jaw_spacing
        n_jaw = int(math.ceil(2 * (jaw.half + self.jaw_margin) / self.jaw_spacing)) + 5 if sd_jaw > 0 else 0
        self._jaw_end = self._jaw0 + n_jaw
        # and the sensor's drift: a rate per reading, the same all run long
        self._drift = self._jaw_end
        self._m = self._jaw_end + (1 if sd_drift > 0 else 0)
        # a part too large for the grid of starts or for the sums over it (8 bytes a basis column a start)
        # is refused before either is built
        check_grid(part, "filter", spacing, grid_size(part, spacing), point_bytes=8.0 * self._m)
        self.tracks = tracks_for(part, spacing, jaw)
        # the faces (start mm, length mm, angle rad) and the starts inside a corner's jump, for the belief
        self._faces = [
            (float(a), float(piece.length), float(piece.tangent_angle(0.0)))
            for a, piece in zip(getattr(part, "starts", ()), getattr(part, "pieces", ()))
            if isinstance(piece, Line)
        ]
        self._inside_corner = self.tracks.pivot & np.roll(self.tracks.pivot, 1)
        self.sd_position = float(sd_position)
        self.sd_scale = float(sd_scale)
        self.sd_slope = float(sd_slope)
        self.sd_jaw = float(sd_jaw)
        self.sd_turn = float(sd_turn)
        self.sd_drift = float(sd_drift)
        self.shape_spacing = float(shape_spacing)
        self.prune = float(prune)
        self.refresh = int(refresh)
        # before the first reference hypothesis: the median radius over the stretches a jaw touches
        convex = self.tracks.kappa[self.tracks.convex & (self.tracks.kappa > 0)]
        self._rho_prior = float(np.clip(np.median(1.0 / convex), 5.0, 500.0)) if convex.size else 50.0
        self.radius = float(radius)
        self.mode_floor = float(mode_floor)
        self.confidence = float(confidence)
        self.index = np.arange(self.tracks.sigma.size)
        self._replaying = 0  # > 0 while a call is made by the filter itself (not logged)
        self.reset()

    @property
    def segment(self) -> int:
        """Index of the present contact segment (0, then one more per :meth:`regrasp`)."""
        return self._segment

    @property
    def grid(self) -> FloatArray:
        """The hypotheses: starts of the rolling, mm."""
        return self.tracks.sigma

    def reset(self) -> None:
        """Back to the prior: every start the jaw can touch equally likely, nothing measured."""
        n = self.grid.size
        self.current = self.grid.copy()  # present contact of each hypothesis, mm (unwrapped)
        self.node = np.arange(n)  # ... and its grid point (on a pivot, the jaw's angle too)
        self.feasible = self.tracks.convex.copy()
        m = self._m
        self._up = np.zeros((m, n))  # Uᵀp per hypothesis (row 0: Σp)
        self._spp = np.zeros(n)
        self._szp = np.zeros(n)
        self._uz = np.zeros(m)  # Uᵀz
        self._uu = np.zeros((m, m))  # UᵀU
        self._szz = 0.0
        self._touched = np.zeros(m, dtype=bool)  # basis columns some reading has touched
        self._touched[0] = True
        # the slope priors' reference and readings done
        self._prior_ref: int | None = None
        self._prior_upto = 0
        self._segment = 0
        self._penalty = np.zeros(n)  # log-probability of the reach evidence (touches, bridges)
        self.jaw_position = math.nan  # the contact's last measured place on the jaw, mm
        self._live = self.feasible.copy()  # hypotheses still worth evaluating
        self._live_idx = np.flatnonzero(self._live)
        self._ref: int | None = None  # the hypothesis whose radii set the slope term's prior
        self._slope_var = np.zeros(self._m)  # prior variance of each slope coefficient, mm²
        self._hist: list[tuple[float, float]] = []  # (z, turn) of every reading, for the reference's radii
        self._version = 0  # changes to the likelihood (its cache's key)
        self._rows = 0  # readings added
        self._cached: dict[float, dict[str, Any]] = {}  # per factor on the slope prior
        self._last_row: tuple[IntArray, FloatArray] = (np.zeros(0, dtype=np.int64), np.zeros(0))
        # every reading as added (weighted): columns, values, z, the hypotheses live then and their
        # predictions, its arc and turn; and the readings taken out again (quarantine)
        self._readings: list[_Reading] = []
        self._out: set[int] = set()
        self._stretch_cache: tuple[Any, float] = (None, 1.0)  # (state, least mass without a stretch)
        self._fit_version = -1  # the state of the readings the last fit test judged
        self._spread_at: tuple[int, bool] = (-1, False)  # (readings, whether they span a defect window)
        self._misfits: list[Misfit] = []  # stretches found not to fit, quarantined (the first MAX_QUARANTINE)
        self._fit_next = FIT_EVERY
        self._last_map = math.nan
        self._last_span: tuple[float, float] | None = None
        self._bridges: list[tuple[float, float, float, float]] = []  # (turn before, turn, jaw, jump)
        # every call that changed the state since the reset, so that the filter can be rebuilt with a
        # stretch quarantined from the start (:meth:`_rebuild`)
        self._calls: list[tuple[str, tuple[Any, ...]]] = []
        # the rolled arc (mm, from, to) of each quarantined stretch: a reading taken there later (the jaw
        # rolled back onto a burr's crest, where it may stay for tens of degrees) is quarantined as it comes
        self._zones: list[tuple[float, float]] = []
        self._add_row(0.0, np.zeros(n))  # the first reading: z_0 = 0, p_0 = 0
        self.steps = 0
        self.turn = 0.0
        self.arc = 0.0

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

    def bridged(self, turn: float, jaw: float | None = None, jump: float = 3.0) -> float:
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

    def _surely_clear(
        self, idx: IntArray, before: float, turn: float, d0: float, jump: float, at: FloatArray | None = None
    ) -> BoolArray:
        """Whether, for each start ``idx``, turning from net rotation ``before`` to ``turn`` (rad) with the
        contact at ``d0`` mm on the jaw surely keeps the jaw on its convex stretch, the contact moving less
        than half of ``jump`` (mm): a bridge there was not to be expected. ``at``: the starts' contacts at
        ``before`` (mm; default: where the tracks put them)."""
        if at is None:
            at, _, _ = self.tracks.step(idx, before)
        # surely clear: still so a little further on (the real part's convex stretch may end up to
        # TURN_MARGIN before the model's)
        further = turn + math.copysign(TURN_MARGIN, turn - before)
        clear = np.ones(idx.size, dtype=bool)
        for t in (turn, further):
            land, node, ok = self.tracks.step(idx, t)
            moved = land - at
            clear &= ok & self.tracks.touches(land, d0 + moved, -self.jaw_margin, sure=True, node=node)
            if t == turn:
                clear &= np.abs(moved) < 0.5 * jump
        out: BoolArray = clear
        return out

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

    def _log(self, name: str, *args: Any) -> None:
        """Keep a call that changes the state (not one the filter makes of itself, nor a replay's)."""
        if not self._replaying:
            self._calls.append((name, args))

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

    def _basis(self, z: float, jaw: float | None = None) -> tuple[IntArray, FloatArray]:
        """(columns, values) of the basis for a reading at cumulative arc z (mm) and place ``jaw`` (mm)
        on the jaw: the segment's offset, four cubic B-splines of the slope error in z (times ρ̂)
        and four of the calibration's error in the place on the jaw."""
        cols, vals = [np.array([self._segment])], [np.array([1.0])]
        if self.sd_slope > 0:
            c, v = _bspline(z / self.shape_spacing)
            c = c + self._segments + self._k0
            if c[0] < self._segments or c[-1] >= self._jaw0:
                raise QueryError(f"arc={z!r} mm is more than a perimeter from the first reading")
            cols.append(c)
            vals.append(v)
        if self.sd_jaw > 0 and jaw is not None:
            # a place read a little beyond the basis' span takes its end's values
            top = self._jaw_end - self._jaw0 - 3 - 1e-9
            x = float(np.clip((float(jaw) - self._jaw_lo) / self.jaw_spacing, 0.0, top))
            c, v = _bspline(x)
            cols.append(c + self._jaw0)
            vals.append(v)
        if self.sd_drift > 0:
            cols.append(np.array([self._drift]))
            vals.append(np.array([float(self._rows - 1)]))
        return np.concatenate(cols), np.concatenate(vals)

    def _radius_here(self) -> float:
        """ρ̂, mm: the model's radius of curvature at the reference hypothesis' present contact
        (5 mm to RHO_MAX; the median convex radius before there is a reference)."""
        if self._ref is None:
            return self._rho_prior
        t = self.tracks
        k = t.kappa[int(t.node_at(self.current[self._ref]))]
        return float(np.clip(1.0 / k, 5.0, RHO_MAX)) if k > 0 else RHO_MAX

    def _slope_priors(self) -> None:
        """Each slope coefficient's prior from the reference hypothesis' radii where its B-spline is
        nonzero: the contact's offset there is ρ·η, η ~ N(0, sd_slope²). Only the prior changes (the
        sums do not depend on it), so the coefficients stay a smooth function of the arc: scaling the
        basis' values by a radius that jumps when the reference changes would make the offset's
        constant part look measured (it is the segments' offsets' to absorb)."""
        if self.sd_slope <= 0 or self._ref is None or not self._hist:
            return
        if self._ref != self._prior_ref:  # a new reference: its radii along the whole path
            self._prior_ref, self._prior_upto = self._ref, 0
            self._slope_var[self._segments : self._jaw0] = 0.0
        new = np.array(self._hist[self._prior_upto :])
        self._prior_upto = len(self._hist)
        if new.size == 0:
            return
        z, turn = new.T
        arc, ok = self.tracks.advance(np.full(z.size, self._ref), turn, turn_margin=TURN_MARGIN)
        land = self.tracks.node_at(np.where(ok, arc, self.grid[self._ref]))
        kappa = self.tracks.kappa[land]
        rho = np.where(kappa > 0, np.clip(1.0 / np.maximum(kappa, 1e-12), 5.0, SLOPE_RHO_MAX), SLOPE_RHO_MAX)
        # column c (relative) is nonzero for z/spacing in [c - 3, c + 1): the largest radius there
        first = np.floor(z / self.shape_spacing).astype(np.int64) + self._segments + self._k0
        for k in range(4):
            np.maximum.at(self._slope_var, first + k, (rho * self.sd_slope) ** 2)
        self._version += 1

    def _add_row(
        self, z: float, p: FloatArray, idx: IntArray | None = None, jaw: float | None = None, turn: float = 0.0
    ) -> None:
        """Add a reading z at net rotation ``turn`` and place ``jaw`` on the jaw with the predictions p of
        the hypotheses ``idx`` (default: all)."""
        self._version += 1
        self._rows += 1
        cols, vals = self._basis(z, jaw)
        self._last_row = (cols, vals)
        self._hist.append((z, turn))
        fresh = cols[(cols >= self._segments) & (cols < self._jaw0)]
        fresh = fresh[self._slope_var[fresh] == 0]
        rho = self._radius_here()
        self._slope_var[fresh] = (min(rho, SLOPE_RHO_MAX) * self.sd_slope) ** 2
        # the rotation's error moves the contact by ρ·e: the reading's variance grows by (ρ̂·sd_turn)²
        # (weighted least squares: the row times 1/relative sd)
        wt = 1.0 / math.hypot(1.0, rho * self.sd_turn / self.sd_position)
        self._row_weight = wt
        z, p, vals = z * wt, p * wt, vals * wt
        live = np.arange(self.grid.size) if idx is None else np.asarray(idx, dtype=np.int64)
        add_row(self._up, self._uu, self._uz, self._spp, self._szp, self._touched, cols, vals, live, p, z)
        self._szz += z * z
        self._readings.append(
            _Reading(cols, vals, z, live, p, z / wt, turn, self._segment, wt, rho if rho < RHO_MAX else 0.0)
        )

    def _take(self, rows: list[int], sign: float) -> None:
        """Take the readings ``rows`` (indices into the readings added) out of the sums (``sign`` -1) or
        put them back (1), for the hypotheses live now."""
        live = self._live_idx
        for j in rows:
            r = self._readings[j]
            pos = np.searchsorted(r.live, live)
            add_row(
                self._up,
                self._uu,
                self._uz,
                self._spp,
                self._szp,
                self._touched,
                r.cols,
                r.vals,
                live,
                r.p[pos],
                r.z,
                sign,
            )
            self._szz += sign * r.z * r.z
        self._version += 1

    def _take_out(self, j: int) -> None:
        """Quarantine reading ``j``, just added (its sums are those of the starts live now)."""
        self._take([j], -1.0)
        self._out.add(j)

    def set_quarantine(self, rows: set[int] | list[int]) -> None:
        """Trust all readings but ``rows`` (indices of the readings in the order given, 0 the first): those
        are taken out of the likelihood, as if never taken; readings quarantined before and not in
        ``rows`` are put back."""
        new = {int(j) for j in rows if 0 < int(j) < len(self._readings)}
        self._take(sorted(new - self._out), -1.0)
        self._take(sorted(self._out - new), 1.0)
        self._out = new

    def _solved(self, factor: float = 1.0) -> dict[str, Any]:
        """The marginalisation over the live hypotheses and their log-likelihoods, with the slope
        prior's standard deviations times ``factor``, once per reading (cached: the reference
        refresh, :meth:`belief` and :meth:`shift` share it)."""
        s = self._cached.get(factor)
        if s is None or s["version"] != self._version:
            s = self._solve(factor)
            s["version"] = self._version
            # the slope prior prunes alone only without an envelope; with one, a start far below the
            # best under one prior may carry the mass under another: :meth:`belief` prunes what is
            # hopeless under all of them
            s["ll"] = self._log_likelihood(s, prune=factor == 1.0 and not self.slope_envelope)
            self._cached[factor] = s
        return s

    def _solve(self, factor: float = 1.0, without: _Sums | None = None, hyps: IntArray | None = None) -> dict[str, Any]:
        """The closed-form marginalisation over the live hypotheses (see the module notes), or over
        ``hyps``; with ``without``, once without each of its stretches of readings (summed over the same
        hypotheses), every array then with a leading axis over the stretches."""
        cols = np.flatnonzero(self._touched)
        s2 = self.sd_position**2
        prior = self._slope_var[cols] * factor**2  # the contact's offset ρ·η: (ρ·sd_slope)²
        prior[cols < self._segments] = 1e6  # the segments' offsets: flat
        prior[(cols >= self._jaw0) & (cols < self._jaw_end)] = self.sd_jaw**2
        prior[cols == self._drift] = self.sd_drift**2
        live = np.flatnonzero(self._live) if hyps is None else np.asarray(hyps, dtype=np.int64)
        uu, uz, szz = self._uu[np.ix_(cols, cols)], self._uz[cols], np.asarray(self._szz)
        v, spp, szp = self._up[np.ix_(cols, live)], self._spp[live], self._szp[live]  # v: (m, n_live)
        if without is not None:
            uu, uz, szz = uu - without.uu, uz - without.uz, szz - without.szz
            v, spp, szp = v - without.up, spp - without.spp, szp - without.szp
        g = uu + np.diag(s2 / prior)
        # an inverse and products, not a solve: with ten thousand starts live a solve for each was most of
        # a belief. Inverted with its diagonal scaled to 1 (its flat offsets' small terms beside the slope
        # terms' large ones make g's condition 10⁸; scaled, 10⁴ on the benchmark's rolling)
        d = 1.0 / np.sqrt(np.diagonal(g, axis1=-2, axis2=-1))
        g_inv = d[..., :, None] * np.linalg.inv(d[..., :, None] * g * d[..., None, :]) * d[..., None, :]
        gi_v, gi_wz = g_inv @ v, np.einsum("...ij,...j->...i", g_inv, uz)
        # ≥ 0 in exact arithmetic (a squared norm after projection); rounding must not make it less
        qpp = np.maximum(spp - np.einsum("...ij,...ij->...j", v, gi_v), 0.0) / s2
        qpz = (szp - np.einsum("...i,...ij->...j", gi_wz, v)) / s2
        qzz = (szz - np.einsum("...i,...i->...", uz, gi_wz))[..., None] / s2  # one per stretch, as the others
        return {
            "cols": cols,
            "g_inv": g_inv,
            "live": live,
            "gi_v": gi_v,
            "gi_wz": gi_wz,
            "qpp": qpp,
            "qpz": qpz,
            "qzz": qzz,
            "k_less": np.zeros(()) if without is None else without.readings,
        }

    def _stack(self, rows: list[int], hyps: IntArray | None = None) -> _Stack:
        """The readings ``rows`` as rows of a matrix over the basis, their values and their predictions at
        the hypotheses live now (or ``hyps``, live): the sums of any stretch of them are then products
        (:func:`_sums`), each reading gathered once however many stretches hold it."""
        live = self._live_idx if hyps is None else np.asarray(hyps, dtype=np.int64)
        cols = np.flatnonzero(self._touched)
        a, z, p = np.zeros((len(rows), cols.size)), np.zeros(len(rows)), np.zeros((len(rows), live.size))
        where: dict[int, IntArray] = {}  # the live hypotheses' places in each set of hypotheses live then
        for n, j in enumerate(rows):
            r = self._readings[j]
            pos = where.get(id(r.live))
            if pos is None:
                pos = where[id(r.live)] = np.searchsorted(r.live, live)
            a[n, np.searchsorted(cols, r.cols)] = r.vals
            z[n] = r.z
            p[n] = r.p[pos]
        return _Stack(cols, a, z, p)

    def _windows(self, rows: list[int], width: float | None = None) -> list[tuple[float, IntArray]]:
        """The stretches of :attr:`defect_window` mm of rolled arc, overlapping by three quarters, over the
        readings ``rows``: (where each begins, mm, and the positions in ``rows`` of its readings), each
        set of readings once."""
        arcs = np.array([self._readings[j].arc for j in rows])
        return stretch_windows(arcs, self.defect_window if width is None else width)

    def _judged_windows(self, rows: list[int]) -> list[tuple[float, IntArray]]:
        """The stretches of the fit test's width over the readings ``rows`` that it can judge: three
        readings at least, and enough outside (:data:`FIT_MIN_READINGS`) to tell misfit from noise."""
        return [
            (a, inside)
            for a, inside in self._windows(rows, self._fit_width)
            if inside.size >= 3 and len(rows) - inside.size >= FIT_MIN_READINGS
        ]

    def _spread(self) -> bool:
        """Whether the trusted readings span more rolled arc than :attr:`defect_window`: else one stretch
        holds them all, and without it nothing is known."""
        if self.defect_window <= 0:
            return True
        if self._spread_at[0] != len(self._readings):
            rows = self._trusted()
            arcs = [self._readings[j].arc for j in rows] or [0.0]
            self._spread_at = (len(self._readings), max(arcs) - min(arcs) > self.defect_window)
        return self._spread_at[1]

    def _jumped(self, j: int) -> bool:
        """Whether reading ``j`` came after a jump of the contact (more than :data:`JUMP_READING` mm of arc
        since the reading before it, in the same segment)."""
        if j < 1:
            return False
        r, q = self._readings[j], self._readings[j - 1]
        # beyond the step the radius then makes of the turn: a plain stretch of 300 mm radius moves a
        # millimetre every 0.2°
        expected = r.radius * abs(r.turn - q.turn)
        return r.segment == q.segment and abs(r.arc - q.arc) - expected > JUMP_READING

    def _trusted(self) -> list[int]:
        """The readings the likelihood holds (not the first, which only places the start; not quarantined)."""
        return [j for j in range(1, len(self._readings)) if j not in self._out]

    def fit_test(self, starts: ArrayLike) -> Misfit | None:
        """Whether the readings still fit the part under each of the hypotheses ``starts`` (grid indices).

        For each start and each stretch of :attr:`defect_window` mm of rolled arc, the stretch's misfit
        per reading against the rest's (the quadratic forms of the marginalisation with and without it:
        every nuisance weighed out, the noise level left to the readings) is an F statistic; its
        p-value, Bonferroni-corrected over the stretches, below :data:`~localizer.FIT_ALPHA` means the
        stretch does not come from the part the model describes there. Noise of any level fits
        (the statistic is a ratio); a burr, a dent, debris or a spike-ridden stretch does not.

        Returns
        -------
        Misfit or None
            None when some start fits every stretch (or there are too few readings to tell); else the
            first start's worst stretch: where on the model (its path's arcs over the stretch), and
            how significant.
        """
        trusted = self._trusted()
        # a reading that came after a jump of the contact (a face crossed, a shallow dip bridged in one
        # step) carries the model's approximation of that jump, one reading's worth: judged by none
        jumps = [j for j in trusted if self._jumped(j)]
        rows = [j for j in trusted if not self._jumped(j)]
        hyps = np.asarray([int(h) for h in np.atleast_1d(starts) if self._live[int(h)]], dtype=np.int64)
        if len(rows) < FIT_MIN_READINGS or hyps.size == 0 or self.defect_window <= 0:
            return None
        t2 = self.sd_scale**2
        # the judged readings first, then the jumps': a stretch's positions in the stack are its own
        stack = self._stack(rows + jumps, hyps)
        at_jumps = np.arange(len(rows), len(rows) + len(jumps))
        q_all = _quad(self._solve(1.0, without=_sums(stack, [at_jumps]), hyps=hyps), t2)[0]
        k = len(rows)
        nuisance = len({self._readings[j].segment for j in rows})
        windows = self._judged_windows(rows)
        if not windows:
            return None
        # what each reading's misfit should be under each start: the row weights were set from one
        # reference start's radius of curvature when the reading came (the rotation reading's error moves
        # the contact by ρ·e), which for another start, or a reference chosen before the readings said
        # much, is not its own: the statistic compares misfit to expectation, stretch against rest
        expect = self._expected_misfit(rows, hyps)  # (len(rows), hyps)
        e_all = expect.sum(axis=0)
        best_p = np.ones(hyps.size)
        best_size = np.zeros(hyps.size)
        best_w: list[tuple[float, IntArray] | None] = [None] * hyps.size
        without = _sums(stack, [np.concatenate([inside, at_jumps]) for _, inside in windows])
        q_rests = np.maximum(_quad(self._solve(1.0, without=without, hyps=hyps), t2), 1e-12)
        for (a, inside), q_rest in zip(windows, q_rests):
            kw, kr = inside.size, k - inside.size - nuisance
            e_w = expect[inside].sum(axis=0)
            stretch = np.maximum(q_all - q_rest, 0.0) / e_w
            rest = q_rest / (e_all - e_w) * k / (k - nuisance)
            f_stat = stretch / rest
            # a misfit the part's: the stretch's readings at least FIT_RATIO times as far off as the rest,
            # and as the noise it was told (the model's own approximations leave a stretch up to about five
            # times off on clean parts; noise-free readings show them alone)
            pv = np.where(stretch >= FIT_RATIO * np.maximum(rest, 1.0), f_dist.sf(f_stat, kw, kr), 1.0)
            better = pv < best_p
            best_p = np.where(better, pv, best_p)
            best_size = np.where(better, stretch, best_size)
            for i in np.flatnonzero(better):
                best_w[i] = (a, inside)
        level = FIT_ALPHA / len(windows)
        if not np.all(best_p < level):
            return None
        a, inside = best_w[0]  # type: ignore[misc]
        chosen = [rows[i] for i in inside]
        return Misfit(
            arcs=self._where(chosen, int(hyps[0])),
            travel=(float(a), float(a + self._fit_width)),
            p_value=float(best_p[0]),
            start=float(self.grid[int(hyps[0])]),
            rows=tuple(chosen),
            rms_mm=float(self.sd_position * math.sqrt(best_size[0])),
        )

    def _best_stretch(self) -> tuple[int, ...]:
        """The stretch (readings) whose absence most improves the best start's likelihood beyond what taking
        out as many readings that fit would (half a unit of the quadratic form each, tempered)."""
        rows = self._trusted()
        best = -math.inf
        s = self._solved(1.0)
        top = float(np.max(s["ll"][s["live"]])) if s["live"].size else -math.inf
        lam2 = float(np.median(s["lam2"])) if s["live"].size else 1.0
        out: tuple[int, ...] = ()
        windows = [inside for _, inside in self._judged_windows(rows)]
        for first, sw in self._without_each(self._stack(rows), windows):
            for inside, ll in zip(windows[first:], sw["ll"]):
                excess = float(np.max(ll)) - top - self.temper * 0.5 * inside.size * lam2
                if excess > best:
                    best, out = excess, tuple(rows[i] for i in inside)
        return out

    def _expected_misfit(self, rows: list[int], hyps: IntArray) -> FloatArray:
        """Each reading's expected weighted misfit (in units of the told reading variance) under each start
        ``hyps``: the reading's own error and the rotation reading's, ρ·sd_turn with ρ the start's radius
        of curvature at its contact then, times the weight the reading was given."""
        here = np.empty((len(rows), hyps.size))
        weight = np.empty(len(rows))
        where: dict[int, IntArray] = {}
        for n, j in enumerate(rows):
            r = self._readings[j]
            pos = where.get(id(r.live))
            if pos is None:
                pos = where[id(r.live)] = np.searchsorted(r.live, hyps)
            here[n] = r.p[pos] / r.weight
            weight[n] = r.weight
        kappa = self.tracks.kappa[self.tracks.node_at(self.grid[hyps][None, :] + here)]
        rho = np.where(kappa > 0, 1.0 / np.maximum(kappa, 1.0 / RHO_MAX), RHO_MAX)
        out: FloatArray = weight[:, None] ** 2 * (1.0 + (rho * self.sd_turn / self.sd_position) ** 2)
        return out

    def stretch_mass(self, arc: float, radius: float | None = None) -> tuple[float, tuple[float, float]]:
        """The least probability within ``radius`` of the present contact at ``arc`` (mm) when any one
        stretch of the readings, ``defect_window`` mm of the rolled arc, is left out, and that stretch
        (cumulative arc, mm, as :meth:`update` took it).

        A burr, a dent or a speck of debris where the jaw rolls makes the readings over it follow a
        shape the model does not have, and a crest's tight bend reads like a fillet of the model: the
        readings of a short stretch alone can look like another place of the part. The belief is sure
        only where it stays sure without any one such stretch (module notes, "A part that is not its
        model"). Each stretch is taken out exactly (the marginalisation without its sums); the windows
        overlap by three quarters, so a stretch up to three quarters of a window lies inside one. Readings
        that span no more than a window are one stretch: without it nothing is known (the least is then
        0). Every live start is weighed; the stretches are tried
        fullest first, and the search stops at the first that leaves less than the confidence (the
        mass returned is then that one's: the belief is not sure, which is what the least decides).
        """
        radius = self.radius if radius is None else float(radius)
        rows = self._trusted()
        if not rows or self.defect_window <= 0:
            return 1.0, (math.nan, math.nan)
        if not self._spread():
            return 0.0, (
                float(min(self._readings[j].arc for j in rows)),
                float(max(self._readings[j].arc for j in rows)),
            )
        hyps = self._live_idx
        stack = self._stack(rows, hyps)
        worst, where = 1.0, (math.nan, math.nan)
        windows = sorted(self._windows(rows), key=lambda w: -w[1].size)
        for first, s in self._without_each(stack, [inside for _, inside in windows], hyps):
            mean, sd = self._shift_of(s)
            for n, ll in enumerate(s["ll"][:, hyps]):
                wts = np.exp(ll - ll.max())
                wts /= wts.sum()
                present = self.part.wrap_arc(self.current[hyps] + mean[n, hyps])
                mass = self._mass_near(wts, present, sd[n, hyps], arc, radius)
                if mass < worst:
                    a = windows[first + n][0]
                    worst, where = mass, (a, a + self.defect_window)
                if worst < self.confidence:
                    return worst, where
        return worst, where

    def _without_each(
        self, stack: _Stack, stretches: list[IntArray], hyps: IntArray | None = None
    ) -> Iterator[tuple[int, dict[str, Any]]]:
        """The marginalisation (:meth:`_solve`, with its log-likelihood) without each stretch of readings
        (positions in ``stack``), a few stretches at a time: (the first one's index, their solve). The
        first batches are small (1, 2, 4, ...): a caller that stops at the first stretch that decides
        pays for few more."""
        first, size = 0, 1
        while first < len(stretches):
            s = self._solve(1.0, without=_sums(stack, stretches[first : first + size]), hyps=hyps)
            s["ll"] = self._log_likelihood(s, prune=False)
            yield first, s
            first, size = first + size, min(2 * size, STRETCH_BATCH)

    def _log_likelihood(self, s: dict[str, Any], prune: bool = True) -> FloatArray:
        """Log-likelihood of each start from a :meth:`_solve` (over the grid, after its leading axis if any),
        the noise scale weighed out; prunes the hopeless ones (of a single solve). Also leaves in ``s`` each
        live start's posterior mean of the squared scale."""
        live, qpp = s["live"], s["qpp"]
        t2 = self.sd_scale**2
        quad = _quad(s, t2)
        # every standard deviation times λ: the quadratic form scales by 1/λ², the determinant by
        # λ^(2k) with k the readings not absorbed by a flat offset; t2·qpp does not change
        k = np.maximum(self._rows - len(self._out) - s["k_less"] - (self._segment + 1), 0).astype(float)
        log_mean, lam2 = weigh_scales(np.atleast_2d(quad), np.atleast_1d(k), np.asarray(self.noise_scales, dtype=float))
        s["lam2"] = lam2.reshape(quad.shape)
        ll_live = self.temper * (log_mean.reshape(quad.shape) - 0.5 * np.log1p(t2 * qpp)) + self._penalty[live]
        ll = np.full(qpp.shape[:-1] + self.grid.shape, -np.inf)
        ll[..., live] = ll_live
        if prune and self.prune > 0 and live.size and qpp.ndim == 1:
            # hypotheses this far below the best are dropped from later evaluations
            drop = live[ll_live < ll_live.max() - self.prune]
            if drop.size:
                self._live[drop] = False
                self._live_idx = np.flatnonzero(self._live)
        return ll

    def _prune_under_every_prior(self) -> None:
        """Drop the live starts more than ``prune`` nats below the best under the slope prior and under
        every factor of the envelope (each judged against its own best)."""
        if not self.prune > 0:
            return
        live = self._live_idx
        hopeless = np.ones(live.size, dtype=bool)
        for factor in (1.0, *self.slope_envelope):
            s = self._solved(factor)
            ll = s["ll"][live]
            hopeless &= ll < ll.max() - self.prune
        if hopeless.any():
            self._live[live[hopeless]] = False
            self._live_idx = np.flatnonzero(self._live)

    def noise_scale(self) -> float:
        """The factor λ on the noise settings that the readings say at the most probable start: the
        root of its posterior mean square (1 when the settings are right)."""
        s = self._solved()
        return float(math.sqrt(s["lam2"][int(np.argmax(s["ll"][s["live"]]))]))

    def log_likelihood(self) -> FloatArray:
        """Log-likelihood of each start (−inf where infeasible or pruned), up to a constant."""
        ll: FloatArray = self._solved()["ll"]
        return ll.copy()

    def shift(self) -> tuple[FloatArray, FloatArray]:
        """How far the real present contact is from each hypothesis' nominal one, mm.

        The slope error η moves the contact for a given jaw angle by ρ·η along the part
        (module notes), so the readings' term ρ̂·η(z) at the last reading is also the
        present contact's offset from where the model puts it. Given the start it is
        Gaussian; with sd_slope = 0 it is zero. The spread also holds the last rotation
        reading's error, which moves the present contact by ρ·e (``sd_turn``).

        Returns
        -------
        mean, sd : ndarray, mm
            Over the grid (0 where infeasible or pruned).
        """
        return self._shift(1.0)

    def _shift(self, factor: float) -> tuple[FloatArray, FloatArray]:
        """:meth:`shift` with the slope prior's standard deviations times ``factor``."""
        return self._shift_of(self._solved(factor))

    def _shift_of(self, s: dict[str, Any]) -> tuple[FloatArray, FloatArray]:
        """:meth:`shift` from the marginalisation ``s`` (:meth:`_solve`, with its log-likelihood; with a
        leading axis as it has)."""
        shape = s["qpp"].shape[:-1] + self.grid.shape
        mean, sd = np.zeros(shape), np.zeros(shape)
        live = s["live"]
        # the last rotation reading's error moves the present contact by ρ·e
        kappa = self.tracks.kappa[self.tracks.node_at(self.current[live])]
        var_turn = (self.sd_turn / np.maximum(kappa, 1.0 / RHO_MAX)) ** 2
        if self.sd_slope <= 0:
            sd[..., live] = np.sqrt(var_turn)
            return mean, sd
        cols = s["cols"]
        a = np.zeros(cols.size)
        row_cols, row_vals = self._last_row
        a[np.searchsorted(cols, row_cols)] = row_vals
        a[cols < self._segments] = 0.0  # the offset is the reading's, not the contact's
        a[cols >= self._jaw0] = 0.0  # so are the calibration's error and the drift
        t2 = self.sd_scale**2
        qpr = s["qpz"] - s["qpp"]
        d_mean = t2 * qpr / (1 + t2 * s["qpp"])  # the scale's posterior, b = 1 + δ
        d_var = t2 / (1 + t2 * s["qpp"])
        a_v = np.einsum("i,...ij->...j", a, s["gi_v"])
        mean[..., live] = np.einsum("i,...i->...", a, s["gi_wz"])[..., None] - (1 + d_mean) * a_v
        # pivoting on a corner the real contact is the corner: machining moves it along the normal
        # only, so it keeps its arc, whatever the slope term says of the stretch before it
        mean[..., live[self.tracks.pivot[self.node[live]]]] = 0.0
        var0 = self.sd_position**2 * np.einsum("i,...i->...", a, np.einsum("...ij,j->...i", s["g_inv"], a))
        # the evidence is tempered (TEMPER): so is what it says of the slope term, whose spread
        # grows by 1/TEMPER in variance as the start's does
        sd[..., live] = np.sqrt(s["lam2"] * (var0[..., None] + d_var * a_v**2) / self.temper + var_turn)
        return mean, sd

    def posterior(self) -> FloatArray:
        """Posterior probability of each start (sums to 1).

        Computed once per reading (a check asks for it several times: the belief and the
        rolling procedure's look-ahead rules)."""
        return self._posterior(1.0)

    def _posterior(self, factor: float) -> FloatArray:
        """:meth:`posterior` with the slope prior's standard deviations times ``factor``."""
        s = self._solved(factor)
        if "w" not in s:
            ll = s["ll"]
            top = ll.max()
            if not np.isfinite(top):
                raise QueryError("no start on the part fits the readings (all hypotheses ruled out)")
            w = np.exp(ll - top)
            s["w"] = w / w.sum()
        posterior: FloatArray = s["w"]
        return posterior.copy()

    def belief(self, radius: float | None = None) -> Belief:
        """The belief over the present contact (see :class:`Belief`), its mass taken within ``radius`` mm
        (default: the filter's ``radius``)."""
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
            # ... and with the contact just past a face counted anywhere on that face's end (module notes)
            mass = min(mass, self._mass_past_faces(w, present, sd, map_arc, radius))
        if self.corner_ends and self.tracks.pivot.any():
            # ... and under a prior that lays the jaw on a corner only at its jump's ends: a pure pivot tells
            # only that the corner's jump is at least the pivot, so the uniform prior over the jump alone
            # would decide between two such corners (module notes, "A jaw laid on a corner")
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
        # sure only if sure without any one short stretch of the readings (a burr, a dent, debris):
        # asked only where it would decide, at the confidence, once per state of the readings
        if mass >= self.confidence and self.defect_window > 0:
            key = (self._version, radius, map_arc)
            if self._stretch_cache[0] != key:
                self._stretch_cache = (key, self.stretch_mass(map_arc, radius)[0])
            mass = min(mass, self._stretch_cache[1])
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
            top = np.argsort(w)[::-1][:FIT_STARTS]
            reps = [i] + [int(self.tracks.node_at(m.start_arc)) for m in strong[1:]]
            reps += [int(h) for h in top if w[h] > 0 and int(h) not in reps]
            found = self.fit_test(reps)
            if found is not None:
                # which stretch to take out: the one whose absence lets some start fit best, not
                # necessarily the one the most probable start misfits (a wrong start that the stretch
                # made probable would otherwise keep it and drop the rest)
                rows = self._best_stretch()
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
        return Belief(
            map_arc=map_arc,
            mass=mass,
            radius=radius,
            modes=tuple(modes),
            ambiguous=ambiguous,
            informative=informative,
            steps=self.steps,
            mismatch=self._where(list(self._misfits[0].rows), i) if self._misfits else None,
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

    def _where(self, rows: list[int], start: int) -> tuple[float, float]:
        """The stretch of the model (arc positions, mm, counter-clockwise from first to last) the contact
        covered over the readings ``rows`` if the rolling started at grid point ``start``."""
        present = []
        for j in rows:
            r = self._readings[j]
            pos = int(np.searchsorted(r.live, start))
            if pos < r.live.size and r.live[pos] == start:
                present.append(self.grid[start] + r.p[pos] / r.weight)
        if not present:
            return (math.nan, math.nan)
        first = present[0]
        rel = np.asarray(self.part.arc_offset(np.array(present), first))
        lo, hi = first + float(rel.min()), first + float(rel.max())
        return float(self.part.wrap_arc(lo)), float(self.part.wrap_arc(hi))

    def _mass_past_faces(self, w: FloatArray, present: FloatArray, sd: FloatArray, arc: float, radius: float) -> float:
        """:meth:`_mass_near`, but a start whose jaw is within :data:`FACE_SLOPES` machined slopes (``sd_slope``)
        of the angle of a face its contact has just left or is about to reach counts as anywhere between that
        face's far end and its contact: the real face, tilted by its machining, may still hold the jaw there.
        The jaw's angle is the start's present node's (on a pivot, within the corner's jump)."""
        part = self.part
        i = int(np.argmax(w))
        sel = np.flatnonzero(w > 1e-12 * w[i])
        p = present[sel]
        theta = np.asarray(self.tracks.theta[self.node[sel]], dtype=float)
        slack = FACE_SLOPES * max(self.sd_slope, 1e-4)
        lo, hi = p.copy(), p.copy()
        wide = np.zeros(p.size, dtype=bool)
        for start, length, angle in self._faces:
            turned = (theta - angle + np.pi) % (2.0 * np.pi) - np.pi
            past = np.asarray(part.arc_offset(p, start + length))  # > 0: beyond the face's end
            before = np.asarray(part.arc_offset(start, p))  # > 0: short of the face's start
            after = (past > 0) & (past < length) & (turned > 0) & (turned <= slack)
            ahead = (before > 0) & (before < length) & (turned < 0) & (turned >= -slack)
            lo = np.where(after, p - past - length, lo)
            hi = np.where(ahead, p + before + length, hi)
            wide |= after | ahead
        if not wide.any():
            return self._mass_near(w, present, sd, arc, radius)
        off_lo = np.asarray(part.arc_offset(lo, arc))
        off_hi = off_lo + (hi - lo)
        overlap = np.clip(np.minimum(off_hi, radius) - np.maximum(off_lo, -radius), 0.0, None)
        inside_wide = overlap / np.maximum(hi - lo, 1e-12)
        inside = self._inside(p, sd[sel], arc, radius)
        return float(np.sum(w[sel] * np.where(wide, inside_wide, inside)))

    def _mass_near(self, w: FloatArray, present: FloatArray, sd: FloatArray, arc: float, radius: float) -> float:
        """Probability that the present contact is within ``radius`` mm of ``arc``: each start's (weight
        ``w``) is N(``present``, ``sd``²) along the part."""
        i = int(np.argmax(w))
        sel = np.flatnonzero(w > 1e-12 * w[i])
        return float(np.sum(w[sel] * self._inside(present[sel], sd[sel], arc, radius)))

    def _inside(self, present: FloatArray, sd: FloatArray, arc: float, radius: float) -> FloatArray:
        """Probability that a contact N(``present``, ``sd``²) along the part is within ``radius`` mm of ``arc``."""
        off = np.asarray(self.part.arc_offset(present, arc))
        spread = np.where(sd > 0, sd, 1.0)
        inside: FloatArray = np.where(
            sd > 0, ndtr((radius - off) / spread) - ndtr((-radius - off) / spread), np.abs(off) <= radius
        )
        return inside

    def _modes(self, w: FloatArray, present: FloatArray, radius: float) -> list[Mode]:
        """Connected groups of probable present contacts, binned at ``radius``."""
        return find_modes(self.part, w, present, self.grid, radius)
