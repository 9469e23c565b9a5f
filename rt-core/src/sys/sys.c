/* placeholder until rt-core lands */
int arflex__sys_placeholder(void);
int arflex__sys_placeholder(void) { return 0; }
