"""``python -m footfall`` runs the command line."""

from footfall.cli import main

main()
