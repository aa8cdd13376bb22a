/* View of willow.l: a strong tropism down, the weeping habit. Widths in model units, like lengths. */
tropism direction: 0,-1,0
initial elasticity: 0.35
line style: cylinder
