"""Fronts over penalties and seeds (``python -m agents.sweep``): :mod:`~agents.sweep.runner`
runs a config (:mod:`~agents.sweep.config`) on Ray Tune (:mod:`~agents.sweep.trial`) or in
worker processes (:mod:`~agents.sweep.processes`); :mod:`~agents.sweep.results` reads the
results folder."""
