"""Feeding an online estimator a stream: the description an estimator and its loop are built from, the loop over
a tracker's samples, reach segmentation, the stream of paired samples, recorded trials, velocities from positions."""
