"""``python -m curvesmith.cli``: the ``curvesmith`` command."""

from . import main

main()
