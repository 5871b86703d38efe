/* plugin_nosym.c: a shared object without a component table (nosym.so), for the error. */
int plugin_nosym_marker(void);

int plugin_nosym_marker(void)
{
    return 42;
}
