"""CLI subcommands, one module each (discovered by :mod:`jointdyn.cli`)."""
