"""Modal parameters, oscillators, curved-beam bending, the wind field and the Simulation."""
