"""What every command shares: click's context settings (``-h`` as well as ``--help``, 100 columns)."""

__all__ = ["CONTEXT"]

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}
