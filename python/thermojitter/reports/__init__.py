"""The reports: figures, tables and Markdown built on the public API, never used by it.

- :mod:`.plots`: every figure, in one style;
- :mod:`.paper`: ``thermojitter paper``, the paper's figures and numbers beside ours;
- :mod:`.beam`: the hinge model against the finite-element beam (``thermojitter beam``);
- :mod:`.distributed`: the hinge model against the coupled distributed panel.

Imports run one way: a report imports the API modules (``thermojitter.beam``,
``thermojitter.simulate``, ...), no API module imports a report.
"""
