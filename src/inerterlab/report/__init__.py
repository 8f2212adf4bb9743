"""The thesis reproduction: tables and figures side by side with the thesis.

Each chapter module (``ch3``, ``ch4_6``, ``studies``, ``ch5``, ``ch7``) exposes two dicts,
``TABLES`` and ``FIGURES``, mapping a thesis id ("4.1", "Fig. 7.9") to a function of
:class:`~inerterlab.report.registry.ReproduceSettings` that returns a
:class:`~inerterlab.report.registry.TableResult` or
:class:`~inerterlab.report.registry.FigureResult`.
"""
