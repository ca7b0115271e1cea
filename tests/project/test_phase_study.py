"""The phase study's choice (studies/does_a_region_per_phase_hold_for_new_people): the count of phases whose coverage
lies nearest 95 % over people and the fractions it scores, and the chance a calibrated region lies within the band."""

import math

import numpy as np

from studies.does_a_region_per_phase_hold_for_new_people import compare_phases as study


def coverage(*by_fraction: float) -> np.ndarray:
    return np.array(by_fraction)


def test_the_count_chosen_is_nearest_95_percent_from_the_scored_fractions_on():
    table = {1: {"P": coverage(0.95, 1.00, 1.00, 0.90, 0.80), "Q": coverage(0.95, 0.98, 0.98, 0.90, 0.85)},
             5: {"P": coverage(0.50, 0.95, 0.96, 0.94, 0.95), "Q": coverage(0.50, 0.94, 0.95, 0.96, 0.93)}}
    assert study.chosen_phases(table) == 5                  # the fraction before SCORED_FROM does not count
    table[5]["Q"] = coverage(0.95, 0.40, 0.95, 0.96, 0.93)  # one person far off at one scored fraction
    assert study.chosen_phases(table) == 1


def test_the_chance_of_lying_within_the_band_is_the_binomial_sum():
    for reaches in (16, 20, 173):
        low, high = math.ceil(study.BAND[0] * reaches - 1e-9), math.floor(study.BAND[1] * reaches + 1e-9)
        direct = sum(math.comb(reaches, k) * 0.95**k * 0.05 ** (reaches - k) for k in range(low, high + 1))
        assert abs(study.band_chance(reaches) - direct) < 1e-12
    assert study.band_chance(16) < 0.6 < study.band_chance(173)
