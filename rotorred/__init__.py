"""rotorred: rotordynamics of dual-rotor machines with rub-impact faults."""
