/* View of seaweed.l: the seed's angle. */
angle increment: 22
initial line width: 0.15 polygons
