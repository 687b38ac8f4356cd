"""The command line: ``rough.cli.main`` holds the group, one module per subcommand."""
