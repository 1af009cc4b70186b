"""Body percentiles: a sex and a percentile -> standing height (m) and body mass (kg).

Source table
------------
Fryar CD, Gu Q, Afful J, Carroll MD, Ogden CL. *Anthropometric Reference Data for Children and
Adults: United States, August 2021–August 2023.* National Center for Health Statistics, Vital and
Health Statistics, Series 3, Number 50, June 2025, pp. 1–28. DOI: 10.15620/cdc/174595
(https://dx.doi.org/10.15620/cdc/174595); the latest edition of the NCHS anthropometric reference
series (its predecessor is Series 3 No. 46, 2015–2018 data, Fryar et al. 2021).

- Table 3, "Weight in kilograms for adults age 20 and older ... selected percentiles, by sex and
  age", rows "20 and older" (male n = 2,688, female n = 3,254; pregnant females excluded).
- Table 7, "Height in centimeters for adults age 20 and older ... selected percentiles, by sex and
  age", rows "20 and older" (male n = 2,690, female n = 3,307).

Population: the civilian noninstitutionalized U.S. population age 20 and older, measured (not
self-reported) in the National Health and Nutrition Examination Survey (NHANES), August 2021 –
August 2023; sample sizes are unweighted, estimates are weighted with the examination weights.
Weight was measured to the nearest 0.1 kg (digital floor scale), standing height to the nearest
0.1 cm (wall-mounted stadiometer). The numbers below are quoted from those two rows as published
(cross-checked against the same rows of Tables 4 and 8, in pounds and inches).

Scaling choice
--------------
The paper's (Assistive Gym's) bodies are called 50th percentile: male 78.4 kg / 1.733 m standing,
female 62.5 kg / 1.584 m (paper §III-A). They are not the NHANES medians (175.2 cm / 86.6 kg for
men), so percentile ``p`` keeps the paper's 50th-percentile body and applies the table's *ratio*
to its own median::

    height(p) = paper_height_50 x stature(p) / stature(50)
    mass(p)   = paper_mass_50   x weight(p)  / weight(50)

so ``p = 50`` is exactly the paper's body and other percentiles spread around it as the U.S.
population does. Between tabulated percentiles the table is interpolated linearly; outside the
tabulated 5th–95th range it is an error (the table has no tails). Height and mass are taken from
the *same* percentile of their own marginal distributions (the usual design-percentile
convention; a real 95th-percentile-stature person is not necessarily at the 95th percentile of
mass). Segment lengths, radii and masses then follow from height and mass as for any person
(:func:`assistive_compiler.person.body.body_for_height`).
"""

from __future__ import annotations

import math
from bisect import bisect_right
from typing import Literal

from .body import DEFAULT_MASS_KG

__all__ = [
    "SOURCE",
    "TABULATED_PERCENTILES",
    "STATURE_CM",
    "WEIGHT_KG",
    "PAPER_50TH_HEIGHT_M",
    "PAPER_50TH_MASS_KG",
    "check_percentile",
    "percentile_height_m",
    "percentile_mass_kg",
    "percentile_body",
]

Sex = Literal["male", "female"]

#: Short citation of the source table, for messages.
SOURCE = (
    "CDC/NCHS Anthropometric Reference Data for Children and Adults: United States, "
    "August 2021–August 2023 (Vital Health Stat 3(50), 2025), Tables 3 and 7, adults 20 and older"
)

#: The percentiles the source tabulates.
TABULATED_PERCENTILES: tuple[float, ...] = (5, 10, 15, 25, 50, 75, 85, 90, 95)

#: Standing height, cm, adults 20 and older, at TABULATED_PERCENTILES (Table 7).
STATURE_CM: dict[str, tuple[float, ...]] = {
    "male": (162.2, 165.2, 167.5, 170.0, 175.2, 180.1, 183.0, 184.8, 187.2),
    "female": (149.6, 152.0, 153.9, 156.4, 161.2, 166.1, 168.6, 170.4, 172.5),
}

#: Body weight, kg, adults 20 and older, at TABULATED_PERCENTILES (Table 3).
WEIGHT_KG: dict[str, tuple[float, ...]] = {
    "male": (60.9, 66.6, 70.0, 75.4, 86.6, 100.6, 111.0, 118.8, 131.8),
    "female": (50.7, 54.7, 57.8, 62.6, 73.5, 89.2, 99.9, 107.2, 119.2),
}

#: The paper's 50th-percentile standing heights (paper §III-A), metres.
PAPER_50TH_HEIGHT_M: dict[str, float] = {"male": 1.733, "female": 1.584}

#: The paper's 50th-percentile masses (paper §III-A), kg.
PAPER_50TH_MASS_KG: dict[str, float] = dict(DEFAULT_MASS_KG)


def check_percentile(percentile: float) -> float:
    """``percentile`` as a float; raises ValueError unless it lies in the tabulated range."""
    if isinstance(percentile, bool) or not isinstance(percentile, (int, float)) or not math.isfinite(percentile):
        raise ValueError(f"percentile must be a number, got {percentile!r}")
    low, high = TABULATED_PERCENTILES[0], TABULATED_PERCENTILES[-1]
    if not low <= percentile <= high:
        raise ValueError(
            f"percentile {percentile:g} is outside the tabulated {low:g}th-{high:g}th "
            f"percentiles of the source table ({SOURCE})"
        )
    return float(percentile)


def _at(values: tuple[float, ...], percentile: float) -> float:
    """Linear interpolation of a tabulated row at ``percentile`` (already checked)."""
    ps = TABULATED_PERCENTILES
    i = min(bisect_right(ps, percentile), len(ps) - 1)
    p0, p1, v0, v1 = ps[i - 1], ps[i], values[i - 1], values[i]
    return v0 + (v1 - v0) * (percentile - p0) / (p1 - p0)


def _sex(sex: str) -> str:
    if sex not in STATURE_CM:
        raise ValueError(f"sex must be 'male' or 'female', got {sex!r}")
    return sex


def percentile_height_m(sex: Sex, percentile: float) -> float:
    """Standing height (m) of the ``percentile`` body of ``sex``: the paper's 50th-percentile
    height x the table's stature ratio to its median."""
    p, rows = check_percentile(percentile), STATURE_CM[_sex(sex)]
    return PAPER_50TH_HEIGHT_M[sex] * (_at(rows, p) / _at(rows, 50))


def percentile_mass_kg(sex: Sex, percentile: float) -> float:
    """Body mass (kg) of the ``percentile`` body of ``sex``: the paper's 50th-percentile mass x
    the table's weight ratio to its median."""
    p, rows = check_percentile(percentile), WEIGHT_KG[_sex(sex)]
    return PAPER_50TH_MASS_KG[sex] * (_at(rows, p) / _at(rows, 50))


def percentile_body(sex: Sex, percentile: float) -> tuple[float, float]:
    """``(standing height m, mass kg)`` of the ``percentile`` body of ``sex``."""
    return percentile_height_m(sex, percentile), percentile_mass_kg(sex, percentile)
