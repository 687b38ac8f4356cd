"""The command line: :mod:`rough.cli.launch` is the ``rough`` entry point (it answers a
bare ``rough --help`` from the stored overview), :mod:`rough.cli.main` holds the group
and :data:`~rough.cli.main.COMMANDS`, the registry of subcommands; one module per
subcommand, and the options they share in :mod:`.options`."""
