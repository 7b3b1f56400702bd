"""``python -m mbdsim ...``: the same command line as the ``mbdsim`` console script."""
from mbdsim.cli.app import main

if __name__ == "__main__":
    main()
