maximum depth: 3
angle factor: 16
initial color: 1
color increment: 1
initial line width: 2 pixels
line width increment: 0.5
viewpoint: 0,0,1
view reference point: 0,0,0
scale factor: 0.9
tropism direction: 0,-1,0
initial elasticity: 0.2
elasticity increment: 0.01
tropism: T: 0,-1,0, A: 0, E: 0.1
/* comment */
