"""``python -m dirac`` does what the ``dirac`` console script does."""

from dirac.cli import main

raise SystemExit(main())
