/* View of default.l: widths in metres, like lengths. */
line style: cylinder
