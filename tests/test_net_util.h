/* test_net_util.h: free loopback TCP ports for tests that start servers. */
#ifndef HEXCNC_TEST_NET_UTIL_H
#define HEXCNC_TEST_NET_UTIL_H

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdio.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

/*
 * n distinct free loopback ports into ports; 0, or -1 when there are not enough. They lie
 * below the kernel's ephemeral range (net.ipv4.ip_local_port_range), where no outgoing
 * connection of any program takes one between this test choosing it and its server binding
 * it: a port from bind(0) is an ephemeral one, and a client connecting in the meantime
 * (the test's own drives, or anything else on the machine) could be given the same number,
 * and the server then cannot listen there. They are taken from 10000 .. 19999 (the Modbus
 * shell tests take theirs from 20000 .. 32000, modbus_test_lib.sh). Each candidate is bound
 * (without SO_REUSEADDR, so one still in TIME_WAIT is passed over too) and all are held
 * until n are found, so they differ; the start is spread by process and time so that
 * parallel runs seldom meet.
 */
static inline int tn_free_ports(int *ports, int n)
{
    int low = 32768;             /* the ephemeral range's first port */
    FILE *f = fopen("/proc/sys/net/ipv4/ip_local_port_range", "r");
    if (f) {
        if (fscanf(f, "%d", &low) != 1)
            low = 32768;
        fclose(f);
    }
    const int first = 10000, end = low < 20000 ? low : 20000;
    if (end - first < 1000 || n < 1 || n > 64)
        return -1;
    int span = end - first, fds[64], found = 0;
    int p = first + (int)(((unsigned)getpid() * 7919u + (unsigned)time(NULL)) % (unsigned)span);
    for (int tried = 0; tried < span && found < n; tried++, p = p + 1 < end ? p + 1 : first) {
        int fd = socket(AF_INET, SOCK_STREAM, 0);
        struct sockaddr_in sa = { .sin_family = AF_INET, .sin_port = htons((uint16_t)p),
                                  .sin_addr.s_addr = htonl(INADDR_LOOPBACK) };
        if (fd < 0)
            break;
        if (bind(fd, (struct sockaddr *)&sa, sizeof sa) == 0)
            fds[found] = fd, ports[found++] = p;
        else
            close(fd);
    }
    for (int i = 0; i < found; i++)
        close(fds[i]);
    return found == n ? 0 : -1;
}

#endif
