"""``python -m dcee.cli``: the ``dcee`` command line."""

from dcee.cli import main

main()
