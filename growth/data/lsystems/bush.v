/* View of bush.l: the seed's angle; a light tropism down, as the seed's Fig. 5. Widths in model units, like lengths. */
angle increment: 22.5
tropism direction: 0,-1,0
initial elasticity: 0.1
line style: cylinder
