"""Parameter identification and hyperparameter optimisation."""
