"""The ``rgbd-eval`` command line (typer); one module per command."""
