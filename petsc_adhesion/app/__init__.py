"""The application: the option table and its reading, one run, studies over MPI, checkpoint files, progress
lines, the command line and the Python API."""
