"""Subcommands of the adfkit CLI, discovered by adfkit.cli."""
