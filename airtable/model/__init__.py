"""What the teacher's app, the student's window and the network share: the scene, the clients,
the seats, the prediction rounds and the teaching aids they exchange. No pygame, no sockets;
imports only the physics."""
