"""The kernel engine of the SVR model kinds: fitting a support vector expansion and evaluating it fast.

:mod:`~greybox.models.kernel.expansion` fits the expansion and holds its frame; :mod:`~greybox.models.kernel.rbf`
evaluates it compiled; :mod:`~greybox.models.kernel.subset` picks training subsets that cover the operating
range. The model classes that use the engine are :mod:`greybox.models.svr` and :mod:`greybox.models.gmssvr`.
"""
