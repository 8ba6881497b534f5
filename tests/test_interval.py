import math

import pytest
from scipy.stats import norm

from lv3d.interval import probability_below, probability_between


@pytest.mark.parametrize("x, mean, sd", [(1.0, 0.0, 1.0), (-2.5, 0.3, 0.7), (90.0, 93.0, 2.0)])
def test_probabilities_are_the_normal_distributions(x, mean, sd):
    assert probability_below(x, mean, sd) == pytest.approx(norm.cdf(x, mean, sd), abs=1e-12)
    assert probability_between(x - sd, x + 2 * sd, mean, sd) == pytest.approx(
        norm.cdf(x + 2 * sd, mean, sd) - norm.cdf(x - sd, mean, sd), abs=1e-12)


def test_an_interval_holds_its_share_of_the_mass():
    # one standard deviation either side of the mean holds 68.3 %; an empty interval nothing; the whole line all
    assert probability_between(-1.0, 1.0, 0.0, 1.0) == pytest.approx(math.erf(1 / math.sqrt(2)), abs=1e-12)
    assert probability_between(2.0, 2.0, 0.0, 1.0) == 0.0
    assert probability_between(-math.inf, math.inf, 5.0, 3.0) == 1.0
    assert probability_below(math.inf, 0.0, 1.0) == 1.0 and probability_below(-math.inf, 0.0, 1.0) == 0.0
