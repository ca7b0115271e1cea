"""Where the hand will be: the model's continuation of a reach from the hand's state, and the kinematic
forecasters beside it."""
