"""``python -m rgbd_eval``: the same as the ``rgbd-eval`` command."""

from rgbd_eval.cli.main import main

if __name__ == "__main__":
    main()
