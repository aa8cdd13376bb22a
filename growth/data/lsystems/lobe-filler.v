/* View of lobe-filler.l: widths in metres, like lengths. */
line style: cylinder
