return { duration = 1.0, rates = { servo = 3000, haptic = 700, physics = 50 } }
