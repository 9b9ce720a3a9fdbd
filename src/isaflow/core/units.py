"""The project's one unit system, declared once.

length cm, force N, time s.  Derived:
- mass: N s^2 / cm (= 100 kg), so that F = m a holds with a in cm/s^2;
- stiffness N/cm, pressure in 2D (force per unit wall length per unit
  thickness) N/cm, specific weight of a 2D liquid (per unit thickness) N/cm^2,
  2D density (mass per unit area per unit thickness) N s^2 / cm^4;
- energy N cm.
A 2D run is per unit thickness (the paper's weights are per unit thickness).
"""

LENGTH = "cm"
FORCE = "N"
TIME = "s"
MASS = "N s2 cm-1"  # 1 N s^2/cm = 100 kg
DENSITY_2D = "N s2 cm-4"  # mass per unit area (per unit thickness)
PRESSURE_2D = "N cm-1"
SPECIFIC_WEIGHT_2D = "N cm-2"
ENERGY = "N cm"
VELOCITY = "cm s-1"

G = 981.0  # cm/s^2, standard gravity 9.81 m/s^2 (g = 9.80665 rounded as is usual in hydraulics)
KG = 0.01  # 1 kg in the mass unit N s^2 / cm
PA = 1e-4  # 1 Pa = 1 N/m^2 in N/cm^2
