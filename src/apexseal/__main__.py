"""``python -m apexseal``: the ``apexseal`` command, for an environment whose scripts folder is not on PATH."""

from apexseal.cli import console

if __name__ == "__main__":
    console()
