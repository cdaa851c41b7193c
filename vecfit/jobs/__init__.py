"""The optimising commands as functions: each makes or reads an initial Scene and ends in
the shared fit-and-write job (fit.py); config.py resolves their settings."""
