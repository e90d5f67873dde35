from ._zcheck import *  # noqa: F401,F403
