/* View of ordinary-tree.l: tropism as The Algorithmic Beauty of Plants' Fig. 2.8a. Widths in model units, like lengths. */
tropism direction: 0,-1,0
initial elasticity: 0.22
line style: cylinder
