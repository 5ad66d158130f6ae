"""The linter habits of ``langur check`` (CLI.md, Diagnostics): configuration, ``# noqa``
suppression, output formats, and the helpers of the transversality analysis
(``langur.transversality``)."""
