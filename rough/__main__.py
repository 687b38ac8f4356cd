"""``python -m rough`` is the ``rough`` command."""

from .cli import main

main()
