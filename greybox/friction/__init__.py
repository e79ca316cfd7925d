"""Physical friction models: Coulomb, Stribeck, LuGre and GMS."""
