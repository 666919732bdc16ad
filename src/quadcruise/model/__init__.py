"""The paper's quadrotor: plant dynamics and rotor actuators."""
