/* View of willow.l: a strong tropism down, the weeping habit. */
tropism direction: 0,-1,0
initial elasticity: 0.35
