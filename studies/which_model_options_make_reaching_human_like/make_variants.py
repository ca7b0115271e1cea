"""Write the one-option variants of the ``human`` preset that the trade-off table of docs/results/calibration.md scores
(studies/which_model_options_make_reaching_human_like/variants/*.yaml), so that every configuration in it can be rebuilt and rerun.

    PYTHONPATH=src python -m studies.which_model_options_make_reaching_human_like.make_variants

Each variant is ``human`` planned open loop (its ``observation`` removed: the variants show what each option
does to the plan a robot predicts) with one change.
"""

from __future__ import annotations

from pathlib import Path

from comanip import presets
from comanip.bodies import PointMass

OUT = Path(__file__).resolve().parent / "variants"


def variants() -> dict:
    """name -> (model, description) for every variant."""
    human = presets.human().replace(observation=())
    body = human.body.inner
    return {
        "paper_damping": (human.replace(body=PointMass(body.n, body.M, 0.3)), "human open loop without the arm viscosity (D = 0.3 N·s/m, the paper's)"),
        "hit_reward": (human.replace(reward="hit"), "human open loop with the saturating 'hit' reward (w as a radius, paper eq. 1)"),
        "effective_width": (human.replace(goal_covariance="effective"), "human open loop with W = (2w/4.133)² I (effective width)"),
        "stopping": (human.replace(stop_weight=1.0), "human open loop with the terminal stopping cost, stop_weight 1 (s/m)²"),
        "hyperbolic": (human.replace(discount="hyperbolic", gamma=0.99), "human open loop with hyperbolic discounting, gamma 0.99"),
    }


def main() -> None:
    OUT.mkdir(exist_ok=True)
    for old in OUT.glob("*.yaml"):
        old.unlink()
    for name, (model, text) in variants().items():
        path = presets.save(model.replace(name=f"human_{name}", description=text), OUT / f"human_{name}.yaml")
        print(path)


if __name__ == "__main__":
    main()
