"""The online estimator: goal estimates of a reach revised with every observation, its options, the explanations
of the hand it asks in order, the whitening of many observations under a plan's belief, and the MAP goal."""
