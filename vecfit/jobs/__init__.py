"""The jobs behind the optimising commands, one shape for all (protocol.py: run(inputs,
config, outputs, progress) -> report): refine, trace, paint, edit, retarget; fit.py is the
fit-and-write they share, config.py resolves their settings from configs/."""
