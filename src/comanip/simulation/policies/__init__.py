"""Robot policies for the synchronisation scenario, one small class per file behind one protocol
(:class:`RobotPolicy` in :mod:`protocol`):

- ``passive`` (:mod:`passive`): zero stiffness, the person does everything (the effort reference);
- ``admittance`` (:mod:`admittance`): the rest height follows the person's force, the person leading it;
- ``prior-only`` (:mod:`prior_only`): the model's reach to the prior goal;
- ``constant-velocity`` (:mod:`constant_velocity`): the hand's current velocity extrapolated;
- ``onset-minimum-jerk`` (:mod:`onset_minimum_jerk`): the height along a minimum-jerk motion of fixed duration
  from the reach's onset;
- ``minimum-jerk`` (:mod:`minimum_jerk_fit`): a Flash–Hogan reach fitted to the observed prefix;
- ``one-shot`` (:mod:`one_shot`): the paper's estimate at t_o, never revised (the scenario's default);
- ``continuous`` (:mod:`continuous`): comanip's online estimate, revised with every observation;
- ``forecast`` (:mod:`forecast`): the same estimate's forecast of the hand as the lead, the robot giving way.

>>> policy = POLICIES["minimum-jerk"](context)      # context: a PolicyContext
"""

from comanip.simulation.policies.admittance import AdmittancePolicy
from comanip.simulation.policies.constant_velocity import ConstantVelocityPolicy
from comanip.simulation.policies.continuous import ContinuousPolicy
from comanip.simulation.policies.forecast import ForecastPolicy
from comanip.simulation.policies.minimum_jerk_fit import MinimumJerkPolicy
from comanip.simulation.policies.one_shot import OneShotPolicy
from comanip.simulation.policies.onset_minimum_jerk import OnsetMinimumJerkPolicy
from comanip.simulation.policies.passive import PassivePolicy
from comanip.simulation.policies.prior_only import PriorOnlyPolicy
from comanip.simulation.policies.protocol import DEFAULT_UPDATE_INTERVAL, PolicyContext, Prediction, RobotPolicy

#: policy name -> class (constructed with a PolicyContext)
POLICIES = {cls.name: cls for cls in (PassivePolicy, AdmittancePolicy, PriorOnlyPolicy, ConstantVelocityPolicy,
                                      OnsetMinimumJerkPolicy, MinimumJerkPolicy, OneShotPolicy, ContinuousPolicy,
                                      ForecastPolicy)}


def check_policy(name) -> str:
    """name if it is a policy of :data:`POLICIES`, else ValueError listing them."""
    if name not in POLICIES:
        raise ValueError(f"policy must be one of {list(POLICIES)}, got {name!r}")
    return name


__all__ = ["AdmittancePolicy", "ConstantVelocityPolicy", "ContinuousPolicy", "DEFAULT_UPDATE_INTERVAL", "ForecastPolicy", "MinimumJerkPolicy", "OneShotPolicy", "OnsetMinimumJerkPolicy", "POLICIES",
           "PassivePolicy", "PolicyContext", "Prediction", "PriorOnlyPolicy", "RobotPolicy", "check_policy"]
