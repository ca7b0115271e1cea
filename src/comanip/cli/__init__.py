"""The ``comanip`` command line: one module per subcommand, registered in :mod:`comanip.cli.main`."""
