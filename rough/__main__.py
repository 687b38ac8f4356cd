"""``python -m rough`` is the ``rough`` command."""

from .cli.launch import main

main()
