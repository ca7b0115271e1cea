"""What is adjusted after an explanation answers: what is learned of a person from their finished reaches, and the
goal smoothed for a robot to follow."""
