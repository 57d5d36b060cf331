"""``python -m holoradar``: the command line (as the ``holoradar`` script)."""

from .app.cli import main

if __name__ == "__main__":
    main()
