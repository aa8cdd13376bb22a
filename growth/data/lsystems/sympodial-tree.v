/* View of sympodial-tree.l: widths in model units, like lengths. */
line style: cylinder
