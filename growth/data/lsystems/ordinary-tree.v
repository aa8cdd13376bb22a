/* View of ordinary-tree.l: tropism as The Algorithmic Beauty of Plants' Fig. 2.8a. */
tropism direction: 0,-1,0
initial elasticity: 0.22
