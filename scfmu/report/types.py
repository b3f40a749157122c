"""What a paper section of the reproduction report is made of (plain data, rendered by ``render``).

Each paper module ``scfmu.report.paperNNN`` exposes ``build(ctx: Context) -> PaperSection``: it runs its
experiments on the campaign engine through ``ctx`` (one Dask client for the whole report), writes its
figures under ``ctx.out_dir / "figures"`` and returns the claims with their evidence and verdicts. The
renderer turns the sections into ``index.html`` and ``report.md``; the paper modules never write HTML.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

CONFIRMED = "confirmed"
NOT_CONFIRMED = "not confirmed"
DEPENDS = "depends on a reading"
# a claim whose outcome the implementation fixes (quantities computed by different routes agree to rounding
# level, e.g. equal gains, a plant copy integrated inside the unit): shown as such, never counted as confirmed
BY_CONSTRUCTION_HOLDS = "holds by construction"
VERDICTS = (CONFIRMED, NOT_CONFIRMED, DEPENDS, BY_CONSTRUCTION_HOLDS)
# verdicts of claims that could have failed (what "At a glance" counts as confirmed / not / depends)
TESTED_VERDICTS = (CONFIRMED, DEPENDS, NOT_CONFIRMED)
# two quantities the claim says are equal, computed by different routes, that agree to within this many
# machine epsilons (relative to their magnitude) agree by construction: no independent computation of
# either lands that close, so the equality is fixed by the implementation and cannot fail
EPS_MULTIPLE = 100.0

# verdicts of a paper's reported number set beside ours (``NumberRow``)
REPRODUCED = "reproduced"            # within 5 % of the paper's value, or within its printed precision
SAME_ORDERING = "same ordering only"  # off, but ranked among the paper's other numbers as the paper ranks it
NOT_REPRODUCED = "not reproduced"
NOT_CHECKABLE = "not checkable"       # the paper lacks what is needed to compute ours (the row says what)
NUMBER_VERDICTS = (REPRODUCED, SAME_ORDERING, NOT_REPRODUCED, NOT_CHECKABLE)

# how a row's "ours" was obtained (``NumberRow.basis``); only an independent row is evidence
INDEPENDENT = "independent"              # computed under the paper's stated set-up, nothing fitted or chosen
CALIBRATED = "calibrated"                # computed from a set-up with a value fitted to a reported number
BY_CONSTRUCTION = "fixed by construction"  # a constraint or a search bound puts the value where it is
CHOSEN = "chosen among readings"         # the set-up was picked among several after comparing with the paper
BASES = (INDEPENDENT, CALIBRATED, BY_CONSTRUCTION, CHOSEN)
# a value within this relative distance of one of its row's bounds (search bounds, optimiser constraints)
# sits on that bound
BOUND_REL = 1e-3


def agrees_by_construction(agreement, multiple: float = EPS_MULTIPLE) -> bool:
    """``agreement`` (the largest relative difference between quantities a claim says are equal, computed by
    different routes) is at rounding level: at most ``multiple`` machine epsilons (``EPS_MULTIPLE``)."""
    import math
    import sys
    try:
        a = float(agreement)
    except (TypeError, ValueError):
        return False
    return math.isfinite(a) and abs(a) <= multiple * sys.float_info.epsilon


def on_bound(value, bounds, rel: float = BOUND_REL):
    """The first of ``bounds`` that ``value`` sits on (within ``rel`` of it, relative to the bound; absolute
    ``rel`` for a bound of 0), or None."""
    import math
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    if not math.isfinite(v):
        return None
    for b in bounds or ():
        b = float(b)
        if abs(v - b) <= rel * (abs(b) if b != 0 else 1.0):
            return b
    return None


@dataclass
class Figure:
    """A PNG under the report folder; ``path`` is relative to it (e.g. "figures/000_ranking.png")."""
    path: str
    caption: str


@dataclass
class Table:
    """A small table; cells are str, int or float (floats are printed with ``digits`` significant digits)."""
    caption: str
    columns: list[str]
    rows: list[list]
    digits: int = 4


@dataclass
class Sensitivity:
    """How a verdict moves with one project-choice reading: the values swept and where the claim holds."""
    parameter: str            # e.g. "FuzzyPdController.e_scale"
    values: list              # values tried (today's default included)
    default: object           # today's default value
    holds_where: str          # e.g. "e_scale ≤ 0.3 rad" or "nowhere in [0.1, 2]" or "everywhere tried"
    figure: Figure | None = None
    table: Table | None = None


@dataclass
class Claim:
    id: str                   # "C000-4", as in the list of the papers' claims
    statement: str            # the paper's claim in our words
    verdict: str              # one of VERDICTS
    evidence: str             # a short paragraph: what we ran and what it showed (plain text)
    tables: list[Table] = field(default_factory=list)
    figures: list[Figure] = field(default_factory=list)
    sensitive_to: list[str] = field(default_factory=list)   # project-choice parameters the verdict depends on
    sensitivity: list[Sensitivity] = field(default_factory=list)
    # the largest relative difference between the quantities the claim says are equal, computed by different
    # routes (None: the claim is no equality); at rounding level (``agrees_by_construction``) a "confirmed"
    # becomes "holds by construction", decided from the numbers, whatever the section said
    agreement: float | None = None
    # readings "chosen among readings" (never evidence) under which the claim holds while the evidence does
    # not confirm it; only with "not confirmed", shown as "not confirmed (holds only under a chosen reading: …)"
    chosen_support: list[str] = field(default_factory=list)

    def __post_init__(self):
        if self.verdict not in VERDICTS:
            raise ValueError(f"{self.id}: verdict {self.verdict!r} is not one of {VERDICTS}")
        if self.verdict == CONFIRMED and agrees_by_construction(self.agreement):
            self.verdict = BY_CONSTRUCTION_HOLDS
            self.evidence += (f" Holds by construction: the quantities compared agree to {float(self.agreement):.2g} "
                              f"(relative), within {EPS_MULTIPLE:g} machine epsilons, so the implementation fixes the "
                              f"outcome and the claim could not have failed; not counted as confirmed.")
        if self.chosen_support and self.verdict != NOT_CONFIRMED:
            raise ValueError(f"{self.id}: support by chosen readings only goes with {NOT_CONFIRMED!r}, not "
                             f"{self.verdict!r}")

    @property
    def verdict_text(self) -> str:
        """The verdict as printed: "not confirmed (holds only under a chosen reading: …)" when chosen readings
        are its only support."""
        if self.chosen_support:
            return f"{self.verdict} (holds only under a chosen reading: {', '.join(self.chosen_support)})"
        return self.verdict


@dataclass
class NumberRow:
    """One reported number of a paper beside ours.

    ``paper_value`` is the number as printed (None when the paper prints none, e.g. a lost table);
    ``paper_text`` how it is printed ("≈ 0.16", "> 50×", "1.44 / 3.44 / 5.44"); ``ours`` our value under the
    paper's stated set-up (None when it cannot be computed); ``basis`` how ours was obtained (``BASES``:
    independent, calibrated, fixed by construction, chosen among readings); ``calibration=True`` is the
    older spelling of ``basis=CALIBRATED``; ``bounds`` the search bounds and optimiser constraints that could
    hold ours in place: a row whose value sits on one of them (``on_bound``) is fixed by construction
    whatever basis it was given, so a bound-hitting value is never counted as evidence; ``note`` says what
    was compared, which reading, the precision rule of the row, or what is missing; ``sensitivity`` (a
    calibrated row) the range of ours across the calibration grid."""
    paper: str
    item: str
    unit: str
    paper_value: float | None
    ours: float | None
    verdict: str
    calibration: bool = False
    note: str = ""
    paper_text: str = ""
    basis: str = INDEPENDENT
    bounds: tuple = ()
    sensitivity: str = ""   # a calibrated row: how ours moves across the calibration grid (shown beside it)
    precision: float | None = None   # the printed-precision half-width the verdict used (the row states its rule)

    def __post_init__(self):
        if self.verdict not in NUMBER_VERDICTS:
            raise ValueError(f"{self.item}: number verdict {self.verdict!r} is not one of {NUMBER_VERDICTS}")
        if self.basis not in BASES:
            raise ValueError(f"{self.item}: basis {self.basis!r} is not one of {BASES}")
        if self.calibration and self.basis == INDEPENDENT:
            self.basis = CALIBRATED
        self.calibration = self.basis == CALIBRATED
        self.bounds = tuple(float(b) for b in self.bounds)
        b = on_bound(self.ours, self.bounds)
        if b is not None and self.basis in (INDEPENDENT, CHOSEN):
            self.basis = BY_CONSTRUCTION
            self.note = (self.note + "; " if self.note else "") + f"ours sits on the bound/constraint {b:g}"

    @property
    def rel_diff(self) -> float:
        """(ours − paper) / |paper|; NaN when either is missing or the paper's value is 0."""
        import math
        if self.paper_value is None or self.ours is None or self.paper_value == 0:
            return math.nan
        try:
            return (float(self.ours) - float(self.paper_value)) / abs(float(self.paper_value))
        except (TypeError, ValueError):
            return math.nan

    @property
    def rule(self) -> str:
        """The reproduction rule of this row as stated beside it: the window of values that reproduce the
        paper's, 5 % or the printed precision, whichever is wider ("" when the row gives no precision)."""
        import math
        if self.precision is None or self.paper_value is None or not math.isfinite(float(self.paper_value)):
            return ""
        p = float(self.paper_value)
        half = max(float(self.precision), 0.05 * abs(p))
        return (f"reproduced within [{p - half:.4g}, {p + half:.4g}]: 5 % or the printed precision "
                f"± {float(self.precision):g}, whichever is wider")

    @property
    def independent(self) -> bool:
        """An independent check: obtained independently (not calibrated, not fixed by a bound or a
        constraint, not chosen after comparison) and something to compare."""
        return self.basis == INDEPENDENT and self.verdict != NOT_CHECKABLE


@dataclass
class PaperSection:
    paper: str                # "000" … "004"
    title: str                # the paper's title
    setup: str                # what we simulated (FMUs, scenarios, run counts, quick or full)
    claims: list[Claim]
    figures: list[Figure] = field(default_factory=list)   # section-level figures (overview plots)
    tables: list[Table] = field(default_factory=list)
    notes: str = ""           # readings, deviations, what differs in --quick
    runtime_s: float = 0.0
    numbers: list[NumberRow] = field(default_factory=list)   # the paper's reported numbers beside ours
    calibrations: str = ""    # which values were fitted to which reported number (plain text)
    doc_tables: dict = field(default_factory=dict)   # {block name: Table} the docs page shows (docs.py)


@dataclass
class Context:
    """Shared by every paper module during one report build."""
    out_dir: Path             # out/report (index.html goes here)
    quick: bool               # reduced run counts/grids for CI
    workers: int              # Dask workers
    client: object = None     # a dask.distributed Client, started once by `scfmu report`

    @property
    def figures_dir(self) -> Path:
        p = self.out_dir / "figures"
        p.mkdir(parents=True, exist_ok=True)
        return p

    def runs_dir(self, name: str) -> Path:
        """Folder for one campaign's results (out/report/runs/<name>); campaigns resume from it."""
        p = self.out_dir / "runs" / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return p

    def campaign(self, c, name: str):
        """Runs a ``scfmu.campaign.Campaign`` on the shared client; returns its results table."""
        from .. import campaign
        return campaign.run(c, self.runs_dir(name), client=self.client, overwrite=True)
