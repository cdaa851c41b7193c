"""The command line (`vecfit`): click commands that resolve settings and run the jobs of
vecfit.jobs, turning user errors into messages and exit codes."""
