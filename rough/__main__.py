"""``python -m rough`` is the ``rough`` command."""

from .cli.main import main

main()
