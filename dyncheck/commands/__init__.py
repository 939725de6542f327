"""One module per command (named as the command; ``options`` holds what they share).
The command line itself — every flag, its help and its example — is :mod:`dyncheck.__main__`."""
