"""What a robot's tree is: joint kinds, the free flyer, link inertials as parameters, the tables
the compiled engine reads, a user's numbers."""
