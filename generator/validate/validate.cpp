// validate: see validate.h
