"""adfkit: author, check, convert and play AMBF Description Format (ADF) scenes."""

__version__ = "0.1.0"
