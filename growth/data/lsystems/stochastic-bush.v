/* View of stochastic-bush.l. */
angle increment: 25.7
initial line width: 0.15 polygons
