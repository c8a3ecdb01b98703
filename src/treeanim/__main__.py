"""``python -m treeanim`` runs the command line."""

from treeanim.cli import main

raise SystemExit(main())
