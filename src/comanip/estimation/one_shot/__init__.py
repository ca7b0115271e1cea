"""The goal from one state observed mid-reach (paper V-C): the regret, its first-order conditions and Newton
iteration, the initial goal, and the posterior over candidate goals."""
