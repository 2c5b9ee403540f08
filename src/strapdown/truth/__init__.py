"""Truth: reference motions with exact attitude and increments, sensor models and vehicle
trajectories. Everything an algorithm is tested against comes from here."""
