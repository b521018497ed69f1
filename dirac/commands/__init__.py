"""One module per ``dirac`` sub-command (see :mod:`dirac.cli`)."""
