"""Direct policy search over a paper's trigger family (``python -m agents.search``): the
algorithm in :mod:`agents.search.cma_es`."""
